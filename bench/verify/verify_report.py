#!/usr/bin/env python3
"""Tables of bench/verify/run_verify_bench.sh from its results folder.

unbumped.txtpb: every unbumped sequence's verdict (false alarms: MOVED) and
the smallest moves each reports it would detect (detectable_*: median, max).
bump_<group>_<axis>_<size>.txtpb: per bump, on how many sequences it was
MOVED with the right direction (the bumped group's difference largest along
the bumped axis, opposite in sign: estimate - reference), and the smallest
size detected on all of them.
"""
import argparse
import os
import re
import statistics
import sys

TOKEN = re.compile(r'\s*(?:([A-Za-z_][A-Za-z0-9_]*)\s*(:)?\s*(\{|"(?:[^"\\]|\\.)*"|[^\s{}]+)?|(\}))')


def parse_text_proto(text):
    """Protobuf text format into nested dicts of lists (enough for these files)."""
    stack = [{}]
    pos = 0
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m or m.end() == pos:
            break
        pos = m.end()
        name, _, value, close = m.groups()
        if close:
            stack.pop()
        elif value == '{':
            child = {}
            stack[-1].setdefault(name, []).append(child)
            stack.append(child)
        elif name is not None and value is not None:
            if value.startswith('"'):
                value = bytes(value[1:-1], 'utf-8').decode('unicode_escape')
            else:
                try:
                    value = float(value)
                except ValueError:
                    pass
            stack[-1].setdefault(name, []).append(value)
    return stack[0]


def field(message, name, default=0.0):
    return message.get(name, [default])[0]


def vector(message, name):
    v = field(message, name, {})
    return [field(v, a) for a in 'xyz'] if v else [0.0, 0.0, 0.0]


def load(path):
    with open(path, encoding='utf-8') as f:
        return parse_text_proto(f.read())


def right_direction(seq, group, axis):
    if group == 'tau':
        return field(seq, 'time_offset_difference_s') < 0.0
    d = vector(seq, 'rotation_difference_deg' if group == 'rotation' else 'translation_difference_m')
    k = 'xyz'.index(axis)
    return max(range(3), key=lambda i: abs(d[i])) == k and d[k] < 0.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--results', required=True, help='the results folder of the bench')
    args = parser.parse_args()

    unbumped = load(os.path.join(args.results, 'unbumped.txtpb'))
    seqs = unbumped.get('sequences', [])
    verdicts = [field(s, 'verdict', 'UNSET') for s in seqs]
    print('Unbumped sequences: %d; HOLDS %d, MOVED %d (false alarms), CANNOT_TELL %d' %
          (len(seqs), verdicts.count('HOLDS'), verdicts.count('MOVED'), verdicts.count('CANNOT_TELL')))
    for s in seqs:
        if field(s, 'verdict', '') != 'HOLDS':
            print('  %s %s: %s' % (field(s, 'name', '?'), field(s, 'verdict', '?'),
                                   ' | '.join(s.get('reasons', [])[:3])))
    chi2 = [field(s, 'chi2') for s in seqs if field(s, 'dof') > 0]
    if chi2:
        print('chi2 of the unbumped: median %.1f, max %.1f (limit %.1f, %d dof)' %
              (statistics.median(chi2), max(chi2), field(seqs[0], 'limit'), field(seqs[0], 'dof')))
    print()
    print('Smallest move each unbumped sequence would detect (median / max over the sequences):')
    print('%-12s %18s %18s %18s' % ('', 'b-x', 'b-y', 'b-z'))
    for name, key, scale, unit in (('rotation', 'detectable_rotation_deg', 1.0, 'deg'),
                                   ('translation', 'detectable_translation_m', 1e3, 'mm')):
        cells = []
        for k in range(3):
            values = [scale * vector(s, key)[k] for s in seqs if vector(s, key)[k] > 0]
            cells.append('%.3g / %.3g %s' % (statistics.median(values), max(values), unit)
                         if values else 'none')
        print('%-12s %18s %18s %18s' % (name, *cells))
    taus = [1e3 * field(s, 'detectable_time_offset_s') for s in seqs
            if field(s, 'detectable_time_offset_s') > 0]
    if taus:
        print('%-12s %18s' % ('tau', '%.3g / %.3g ms' % (statistics.median(taus), max(taus))))
    print()

    bumps = {}
    for f in sorted(os.listdir(args.results)):
        m = re.match(r'bump_(rotation|translation|tau)_(?:([xyz])_)?([0-9.e-]+)\.txtpb$', f)
        if not m:
            continue
        group, axis, size = m.group(1), m.group(2) or '', float(m.group(3))
        result = load(os.path.join(args.results, f))
        detected = 0
        total = 0
        for s in result.get('sequences', []):
            total += 1
            if field(s, 'verdict', '') == 'MOVED' and right_direction(s, group, axis):
                detected += 1
        bumps.setdefault((group, axis), []).append((size, detected, total))
    print('Bumps of the reference (detected with the right direction / sequences):')
    units = {'rotation': (1.0, 'deg'), 'translation': (1e3, 'mm'), 'tau': (1e3, 'ms')}
    for (group, axis), rows in sorted(bumps.items()):
        scale, unit = units[group]
        rows.sort()
        smallest = next((size for size, d, t in rows if t > 0 and d == t), None)
        cells = ', '.join('%g %s: %d/%d' % (scale * size, unit, d, t) for size, d, t in rows)
        label = group + (' ' + ('about' if group == 'rotation' else 'along') + ' b-' + axis
                         if axis else '')
        print('  %-24s %s; smallest detected on all: %s' %
              (label, cells, '%g %s' % (scale * smallest, unit) if smallest else 'none tried'))
    return 0


if __name__ == '__main__':
    sys.exit(main())
