#!/usr/bin/env python3
"""Is the reported covariance honest? For calibrations of simulated
sequences, the errors against the simulator's truth in units of the reported
sigma should look standard normal.

Usage: covariance_consistency.py CALIBRATION.txtpb:TRUTH.txtpb [...]

Per run: the error e = (Log(C_true^T C_est) [rad, the covariance's right
perturbation], r_est - r_true [m], tau_est - tau_true [s]), its NEES
e^T P^-1 e with P the reported 7x7 covariance (chi-square with 7 degrees of
freedom when P is right: mean 7), and the per-component z-scores e_i / sigma_i
(standard normal: mean 0, RMS 1). Prints one row per run and the summary over
the runs: mean NEES with its two-sided 95 % interval for N runs
(chi-square(7N)/N, Wilson-Hilferty), RMS of each component's z-scores.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_errors import get, parse, qmul, quat, vec  # noqa: E402

NAMES = ['rot_x', 'rot_y', 'rot_z', 'r_x', 'r_y', 'r_z', 'tau']


def log_quaternion(q):
    w, x, y, z = q
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    n = math.sqrt(x * x + y * y + z * z)
    if n < 1e-15:
        return [2 * x, 2 * y, 2 * z]
    angle = 2 * math.atan2(n, w)
    return [angle * x / n, angle * y / n, angle * z / n]


def solve(a, b):
    """x with a x = b (Gauss-Jordan with partial pivoting)."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(n):
            if r != c:
                f = m[r][c] / m[c][c]
                m[r] = [vr - f * vc for vr, vc in zip(m[r], m[c])]
    return [m[i][n] / m[i][i] for i in range(n)]


def chi2_quantile(p, k):
    """Wilson-Hilferty approximation of the chi-square quantile."""
    z = {0.025: -1.959964, 0.975: 1.959964}[p]
    return k * (1 - 2 / (9 * k) + z * math.sqrt(2 / (9 * k))) ** 3


def true_time_offset(cal, truth):
    """The truth's tau where the calibration's time_offset_s refers to: at t=0
    (truth time_offset_s), or, with the clock drift estimated, at its
    reference time (LiDAR clock, s from the first IMU stamp), interpolated
    between the truth scans' true_stamp_ns - stamp_ns."""
    if get(cal, 'time_offset_drift.estimated', 'false') != 'true':
        return get(truth, 'time_offset_s')
    t_ref = get(cal, 'time_offset_drift.reference_time_s')
    start = get(truth, 'start_stamp_ns')
    points = [((get(s, 'stamp_ns') - start) * 1e-9, (get(s, 'true_stamp_ns') - get(s, 'stamp_ns')) * 1e-9)
              for s in truth.get('scans', [])]
    for (t0, a), (t1, b) in zip(points, points[1:]):
        if t0 <= t_ref <= t1:
            return a + (b - a) * (t_ref - t0) / (t1 - t0) if t1 > t0 else a
    return get(truth, 'time_offset_s')


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    nees, zs = [], []
    print('%-44s %8s  %s' % ('run', 'NEES', '  '.join('%6s' % n for n in NAMES)))
    for arg in sys.argv[1:]:
        cal_path, truth_path = arg.split(':')
        cal = parse(open(cal_path).read())
        truth = parse(open(truth_path).read())
        q_est = quat(cal, 'imu_from_lidar.rotation')
        q_true = quat(truth, 'imu_from_lidar.rotation')
        e = log_quaternion(qmul([q_true[0], -q_true[1], -q_true[2], -q_true[3]], q_est))
        e += [a - b for a, b in zip(vec(cal, 'imu_from_lidar.translation'),
                                    vec(truth, 'imu_from_lidar.translation'))]
        e.append(get(cal, 'time_offset_s') - true_time_offset(cal, truth))
        cov = cal.get('covariance', [])
        if len(cov) != 49:
            print('%s: no 7x7 covariance' % cal_path)
            continue
        p = [cov[7 * i:7 * i + 7] for i in range(7)]
        n = sum(a * b for a, b in zip(e, solve(p, e)))
        z = [e[i] / math.sqrt(p[i][i]) for i in range(7)]
        nees.append(n)
        zs.append(z)
        label = cal_path
        print('%-44s %8.2f  %s  %s' % (label[-44:], n, '  '.join('%6.2f' % v for v in z),
                                       get(cal, 'verdict', '')))
    if not nees:
        return
    k = 7 * len(nees)
    print('runs %d: mean NEES %.2f (7 expected; 95 %% interval for %d runs [%.2f, %.2f])' % (
        len(nees), sum(nees) / len(nees), len(nees), chi2_quantile(0.025, k) / len(nees),
        chi2_quantile(0.975, k) / len(nees)))
    print('RMS z per component (1 expected): ' + ', '.join(
        '%s %.2f' % (NAMES[i], math.sqrt(sum(z[i] ** 2 for z in zs) / len(zs)))
        for i in range(7)))


if __name__ == '__main__':
    main()
