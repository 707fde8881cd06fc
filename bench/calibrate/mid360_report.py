#!/usr/bin/env python3
"""Report of bench/calibrate/run_mid360_seeds.sh: per run the errors of the
extrinsic against the simulator's truth, the rotation split into the angle
about up (yaw: about the motion's rotation axis on level ground, the weakly
observed one) and the tilt about the horizontal axes, the translation in
the plane of motion, |tau| and the verdict; then per params label the RMS
and maximum over the seeds and the verdicts that were not OK.

Usage: mid360_report.py results.tsv   (lines: label, seed, work dir)
"""
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_errors import parse, quat, qmul  # noqa: E402
from scaling_report import errors, up_in_imu  # noqa: E402


def yaw_tilt_deg(cal, truth):
    """The rotation error split into its angle about up and the rest (deg)."""
    q = quat(truth, 'imu_from_lidar.rotation')
    d = qmul(quat(cal, 'imu_from_lidar.rotation'), (q[0], -q[1], -q[2], -q[3]))
    if d[0] < 0:
        d = [-x for x in d]
    s = math.sqrt(d[1] ** 2 + d[2] ** 2 + d[3] ** 2)
    angle = 2.0 * math.atan2(s, d[0])
    phi = [angle * d[i] / s for i in (1, 2, 3)] if s > 0 else [0.0, 0.0, 0.0]
    about_up = sum(p * u for p, u in zip(phi, up_in_imu(truth)))
    tilt = math.sqrt(max(0.0, sum(p * p for p in phi) - about_up ** 2))
    return math.degrees(abs(about_up)), math.degrees(tilt)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    runs = []
    for line in open(sys.argv[1]):
        label, seed, work = line.rstrip('\n').split('\t')
        text = open(os.path.join(work, 'calibration_%s.txtpb' % label)).read()
        truth = parse(open(os.path.join(work, 'truth.txtpb')).read())
        verdict = re.search(r'^verdict: (\w+)', text, re.M)
        cal = parse(text)
        _, planar_cm, tau_ms = errors(cal, truth)
        yaw_deg, tilt_deg = yaw_tilt_deg(cal, truth)
        runs.append((label, seed, yaw_deg, tilt_deg, planar_cm, abs(tau_ms),
                     verdict.group(1) if verdict else 'OK'))
    print('%-24s %5s %8s %8s %10s %8s %8s' % ('params', 'seed', 'yaw_deg', 'tilt_deg',
                                              'planar_cm', 'tau_ms', 'verdict'))
    for r in runs:
        print('%-24s %5s %8.4f %8.4f %10.3f %8.3f %8s' % r)
    labels = []
    for r in runs:
        if r[0] not in labels:
            labels.append(r[0])
    rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v))
    for label in labels:
        sel = [r for r in runs if r[0] == label]
        cols = list(zip(*sel))
        not_ok = [r[1] + ' ' + r[6] for r in sel if r[6] != 'OK']
        print('\n%s: %d seeds, RMS (max): yaw %.4f (%.4f) deg, tilt %.4f (%.4f) deg, planar '
              '%.3f (%.3f) cm, tau %.3f (%.3f) ms; not OK: %s' % (
                  label, len(sel), rms(cols[2]), max(cols[2]), rms(cols[3]), max(cols[3]),
                  rms(cols[4]), max(cols[4]), rms(cols[5]), max(cols[5]),
                  ', '.join('seed ' + x for x in not_ok) or 'none'))


if __name__ == '__main__':
    main()
