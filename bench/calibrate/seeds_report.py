#!/usr/bin/env python3
"""Report of bench/calibrate/run_seeds_bench.sh: one row per calibrate run
(wall, CPU = user + sys, the CPU time other guests took meanwhile (steal),
the odometry phase, LM iterations, the errors against the truth), then per
binary: the mean and range of the wall time, the runs over the wall goal,
the mean CPU and odometry, the steal in all, the same means over the runs
that lost less than 0.5 s to steal, and the errors over the seeds (RMS and
maximum of the rotation in deg, the planar translation in cm and |tau| in
ms, from the first pass: a binary gives the same estimate on every pass,
and the report says so when it did not); last the anchor / this ratios.

Usage: seeds_report.py results.tsv [--wall_goal S]
       (lines of results.tsv: pass, label, work dir, steal ticks, ticks per s)
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_errors import get, parse  # noqa: E402
from scaling_report import errors, gnu_time, phase  # noqa: E402

QUIET_STEAL_S = 0.5


def load(results_path):
    runs = []
    for line in open(results_path):
        pass_, label, work, steal_ticks, ticks_per_s = line.rstrip('\n').split('\t')
        cal = parse(open(os.path.join(work, 'calibration_%s_%s.txtpb' % (label, pass_))).read())
        truth = parse(open(os.path.join(work, 'truth.txtpb')).read())
        wall, cpu, _ = gnu_time(os.path.join(work, 'time_%s_%s.txt' % (label, pass_)))
        rot, planar, tau = errors(cal, truth)
        runs.append(dict(pass_=int(pass_), label=label, seed=os.path.basename(work), wall=wall,
                         cpu=cpu, steal=float(steal_ticks) / float(ticks_per_s),
                         odometry=phase(cal, 'init_lidar_odometry'),
                         iterations=get(cal, 'solver.iterations'), rot=rot, planar=planar, tau=tau))
    return runs


def mean(values):
    return sum(values) / len(values) if values else float('nan')


def rms(values):
    return math.sqrt(mean([v * v for v in values])) if values else float('nan')


def summary(runs, wall_goal):
    walls = [r['wall'] for r in runs]
    quiet = [r for r in runs if r['steal'] < QUIET_STEAL_S]
    first = [r for r in runs if r['pass_'] == 1]
    by_seed = {}
    for r in runs:
        by_seed.setdefault(r['seed'], set()).add((round(r['rot'], 9), round(r['planar'], 9)))
    return dict(
        n=len(runs), wall=mean(walls), wall_min=min(walls), wall_max=max(walls),
        over=sum(w > wall_goal for w in walls), cpu=mean([r['cpu'] for r in runs]),
        odometry=mean([r['odometry'] for r in runs]), steal=sum(r['steal'] for r in runs),
        n_quiet=len(quiet), wall_quiet=mean([r['wall'] for r in quiet]),
        cpu_quiet=mean([r['cpu'] for r in quiet]),
        rot_rms=rms([r['rot'] for r in first]), rot_max=max(r['rot'] for r in first),
        planar_rms=rms([r['planar'] for r in first]), planar_max=max(r['planar'] for r in first),
        tau_rms=rms([r['tau'] for r in first]), tau_max=max(abs(r['tau']) for r in first),
        iterations=mean([r['iterations'] for r in first]),
        same_every_pass=all(len(v) == 1 for v in by_seed.values()))


def main():
    args = sys.argv[1:]
    wall_goal = 10.0
    if '--wall_goal' in args:
        i = args.index('--wall_goal')
        wall_goal = float(args[i + 1])
        del args[i:i + 2]
    if len(args) != 1:
        sys.exit(__doc__)
    runs = load(args[0])
    if not runs:
        sys.exit('seeds_report: no runs in %s' % args[0])
    print('%-6s %-6s %4s %7s %7s %7s %8s %5s %9s %9s %8s' % (
        'label', 'seed', 'pass', 'wall_s', 'cpu_s', 'steal_s', 'odom_s', 'LM', 'rot_deg',
        'planar_cm', 'tau_ms'))
    for r in runs:
        print('%-6s %-6s %4d %7.2f %7.2f %7.2f %8.2f %5d %9.4f %9.3f %8.3f' % (
            r['label'], r['seed'], r['pass_'], r['wall'], r['cpu'], r['steal'], r['odometry'],
            r['iterations'], r['rot'], r['planar'], r['tau']))
    summaries = {}
    for label in ('anchor', 'this'):
        selected = [r for r in runs if r['label'] == label]
        if not selected:
            continue
        s = summaries[label] = summary(selected, wall_goal)
        print('\n%s: %d runs; wall %.2f s mean (%.2f-%.2f), %d over %.1f s; CPU %.2f s; odometry '
              '%.2f s; steal %.1f s in all; the %d runs with < %.1f s of steal: wall %.2f s, '
              'CPU %.2f s' % (label, s['n'], s['wall'], s['wall_min'], s['wall_max'], s['over'],
                              wall_goal, s['cpu'], s['odometry'], s['steal'], s['n_quiet'],
                              QUIET_STEAL_S, s['wall_quiet'], s['cpu_quiet']))
        print('  errors over the seeds, RMS (max): rotation %.4f (%.4f) deg, planar %.3f (%.3f) cm, '
              'tau %.3f (%.3f) ms; LM iterations %.1f mean%s' % (
                  s['rot_rms'], s['rot_max'], s['planar_rms'], s['planar_max'], s['tau_rms'],
                  s['tau_max'], s['iterations'],
                  '' if s['same_every_pass'] else '; NOT the same estimate on every pass'))
    if len(summaries) == 2:
        a, t = summaries['anchor'], summaries['this']
        print('\nanchor / this: wall %.2f, CPU %.2f, odometry %.2f, wall of the quiet runs %.2f' % (
            a['wall'] / t['wall'], a['cpu'] / t['cpu'], a['odometry'] / t['odometry'],
            a['wall_quiet'] / t['wall_quiet']))


if __name__ == '__main__':
    main()
