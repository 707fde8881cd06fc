#!/usr/bin/env python3
"""Table of bench/calibrate/run_scaling_bench.sh: one row per calibrate run
(wall, cpu, peak memory, odometry and solve phases, wall per second of data,
errors against the truth), the exponent b of a least-squares fit
log(wall) = log(a) + b log(duration) per binary, and anchor / this ratios.

With --plot FILE.png it also draws, per binary, the CPU and wall seconds
per second of data and the peak memory per second of data against the
duration (log duration axis; a flat line is linear cost). The plot needs matplotlib (Debian's
python3-matplotlib, in /usr/bin/python3).

Usage: scaling_report.py results.tsv [--plot FILE.png]
       (lines of results.tsv: duration_s, label, work dir)
"""
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_errors import angle_deg, get, parse, quat, vec  # noqa: E402


def gnu_time(path):
    text = open(path).read()

    def field(name):
        m = re.search(re.escape(name) + r':\s*(\S+)', text)
        return m.group(1) if m else '0'
    wall = field('Elapsed (wall clock) time (h:mm:ss or m:ss)')
    seconds = 0.0
    for part in wall.split(':'):
        seconds = seconds * 60 + float(part)
    cpu = float(field('User time (seconds)')) + float(field('System time (seconds)'))
    return seconds, cpu, float(field('Maximum resident set size (kbytes)')) / 1024.0


def up_in_imu(truth):
    """Unit up in b, the normal of the plane of motion: -g_f (flat ground), else -g at t0."""
    up = vec(truth, 'gravity_flat_in_imu')
    if not any(up):
        up = vec(truth, 'gravity_in_world')
    n = math.sqrt(sum(x * x for x in up))
    return [-x / n for x in up]


def errors(cal, truth):
    """Rotation error (deg), translation error in the plane of motion (cm), tau error (ms)."""
    rot = angle_deg(quat(cal, 'imu_from_lidar.rotation'), quat(truth, 'imu_from_lidar.rotation'))
    up = up_in_imu(truth)
    dt = [e - t for e, t in zip(vec(cal, 'imu_from_lidar.translation'),
                                vec(truth, 'imu_from_lidar.translation'))]
    vertical = sum(a * b for a, b in zip(dt, up))
    planar = math.sqrt(max(0.0, sum(x * x for x in dt) - vertical ** 2))
    tau = (get(cal, 'time_offset_s') - get(truth, 'time_offset_s')) * 1e3
    return rot, planar * 100, tau


def phase(cal, name):
    return sum(get(t, 'seconds') for t in cal.get('timings', []) if get(t, 'phase', '') == name)


def fit_exponent(points):
    if len(points) < 2:
        return float('nan')
    xs = [math.log(d) for d, _ in points]
    ys = [math.log(w) for _, w in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float('nan')


def plot(rows, path):
    try:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
    except ImportError:
        print('no plot: matplotlib is missing (Debian python3-matplotlib, /usr/bin/python3)')
        return
    fig, (per_second, memory) = plt.subplots(1, 2, figsize=(11, 4.2))
    for label, colour in (('this', 'tab:blue'), ('anchor', 'tab:gray')):
        mine = sorted((r for r in rows if r['label'] == label), key=lambda r: r['d'])
        if not mine:
            continue
        d = [r['d'] for r in mine]
        per_second.plot(d, [r['cpu'] / r['d'] for r in mine], 'o-', color=colour,
                        label='%s: CPU (exponent %.2f)' % (label, fit_exponent(
                            [(r['d'], r['cpu']) for r in mine])))
        per_second.plot(d, [r['wall'] / r['d'] for r in mine], 's--', color=colour,
                        label='%s: wall (exponent %.2f)' % (label, fit_exponent(
                            [(r['d'], r['wall']) for r in mine])))
        memory.plot(d, [r['mem'] / r['d'] for r in mine], 'o-', color=colour, label=label)
    for axis in (per_second, memory):
        axis.set_xscale('log', base=2)
        axis.set_xlabel('sequence duration, s')
        axis.grid(True, which='both', alpha=0.3)
        axis.legend(fontsize=8)
    per_second.set_ylabel('s per second of data (flat = linear cost)')
    per_second.set_ylim(bottom=0)
    memory.set_ylabel('peak resident memory per second of data, MB')
    memory.set_ylim(bottom=0)
    fig.suptitle('tiltcal_calibrate scaling')
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    print('plot: %s' % path)


def main():
    args = sys.argv[1:]
    plot_path = None
    if '--plot' in args:
        i = args.index('--plot')
        plot_path = args[i + 1]
        del args[i:i + 2]
    rows = []
    for line in open(args[0]):
        d, label, w = line.rstrip('\n').split('\t')
        wall, cpu, mem_mb = gnu_time(os.path.join(w, 'time_%s.txt' % label))
        cal = parse(open(os.path.join(w, 'calibration_%s.txtpb' % label)).read())
        truth = parse(open(os.path.join(w, 'truth.txtpb')).read())
        rows.append(dict(d=float(d), label=label, wall=wall, cpu=cpu, mem=mem_mb,
                         odo=phase(cal, 'init_lidar_odometry'), solve=phase(cal, 'solve'),
                         solve_cpu=phase(cal, 'solve_cpu'),
                         iters=get(cal, 'solver.iterations'),
                         rounds=get(cal, 'solver.outer_iterations'),
                         err=errors(cal, truth)))
    print('%6s %-6s %8s %8s %8s %8s %8s %9s %6s %6s %8s %10s %8s' % (
        'dur_s', 'binary', 'wall_s', 'cpu_s', 'peak_MB', 'odom_s', 'solve_s', 'solve_cpu', 'LM_it',
        'rounds', 'wall/dur', 'rot_deg', 'plane_cm') + '   tau_ms')
    for r in rows:
        print('%6.0f %-6s %8.2f %8.2f %8.0f %8.2f %8.2f %9.2f %6d %6d %8.3f %10.4f %8.3f %8.3f' % (
            r['d'], r['label'], r['wall'], r['cpu'], r['mem'], r['odo'], r['solve'], r['solve_cpu'],
            r['iters'], r['rounds'], r['wall'] / r['d'], r['err'][0], r['err'][1], r['err'][2]))
    for label in ('this', 'anchor'):
        pts = [(r['d'], r['wall']) for r in rows if r['label'] == label]
        cpts = [(r['d'], r['cpu']) for r in rows if r['label'] == label]
        if pts:
            print('%-6s log-log exponent: wall %.2f, cpu %.2f (1 = linear in the duration)' % (
                label, fit_exponent(pts), fit_exponent(cpts)))
    by = {(r['d'], r['label']): r for r in rows}
    for d in sorted({r['d'] for r in rows}):
        if (d, 'this') in by and (d, 'anchor') in by:
            a, t = by[(d, 'anchor')], by[(d, 'this')]
            print('%4.0f s: anchor / this  wall %.2f  cpu %.2f  odometry %.2f  solve %.2f  peak memory %.2f'
                  % (d, a['wall'] / t['wall'], a['cpu'] / t['cpu'],
                     a['odo'] / max(t['odo'], 1e-9), a['solve'] / max(t['solve'], 1e-9),
                     a['mem'] / t['mem']))
    if plot_path:
        plot(rows, plot_path)


if __name__ == '__main__':
    main()
