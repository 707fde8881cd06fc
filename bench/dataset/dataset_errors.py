#!/usr/bin/env python3
"""Errors of a dataset's joint calibration (out/calibration.txtpb of
tiltcal_dataset_calibration) and of its sequences' own calibrations against
the simulator's truth, in units of the reported sigma.

Usage: dataset_errors.py DATASET_DIR

Rotation errors are e = Log(C_true^T C_est) (rad, frame l, the covariance's
right perturbation), split into the vertical (about C_bl^T up_b, up_b the
vehicle's up in b, -g_f of the truth) and the two tilt directions;
translations per axis of b, mm. Prints, per sequence, the tilt and vertical
z-scores, and for the joint value the errors, their z-scores, and the joint
sigma about the vertical against the sequences' mean.
"""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'calibrate'))
from calibration_errors import get, parse, qmul, quat, vec  # noqa: E402
from covariance_consistency import log_quaternion  # noqa: E402


def rotate(q, v):
    w, x, y, z = q
    p = qmul(qmul(q, [0.0] + list(v)), [w, -x, -y, -z])
    return p[1:]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def errors(cal, truth):
    """(rotation error e [rad, frame l], translation error [m, b], P 7x7)."""
    q_est = quat(cal, 'imu_from_lidar.rotation')
    q_true = quat(truth, 'imu_from_lidar.rotation')
    e = log_quaternion(qmul([q_true[0], -q_true[1], -q_true[2], -q_true[3]], q_est))
    t = [a - b for a, b in zip(vec(cal, 'imu_from_lidar.translation'),
                               vec(truth, 'imu_from_lidar.translation'))]
    cov = cal.get('covariance', [])
    p = [cov[7 * i:7 * i + 7] for i in range(7)] if len(cov) == 49 else None
    return e, t, p


def directions(truth):
    """Unit vectors in l: the vertical and two tilt axes."""
    q_true = quat(truth, 'imu_from_lidar.rotation')
    g = vec(truth, 'gravity_flat_in_imu')  # the vehicle's vertical, frame b
    n = math.sqrt(dot(g, g)) or 1.0
    up_b = [-x / n for x in g]
    q_inv = [q_true[0], -q_true[1], -q_true[2], -q_true[3]]
    up_l = rotate(q_inv, up_b)
    helper = [1.0, 0.0, 0.0] if abs(up_l[0]) < 0.9 else [0.0, 1.0, 0.0]
    a = [helper[1] * up_l[2] - helper[2] * up_l[1], helper[2] * up_l[0] - helper[0] * up_l[2],
         helper[0] * up_l[1] - helper[1] * up_l[0]]
    na = math.sqrt(dot(a, a))
    a = [x / na for x in a]
    b = [up_l[1] * a[2] - up_l[2] * a[1], up_l[2] * a[0] - up_l[0] * a[2],
         up_l[0] * a[1] - up_l[1] * a[0]]
    return {'vertical': up_l, 'tilt_a': a, 'tilt_b': b}


def sigma_along(p, u):
    return math.sqrt(sum(u[i] * p[i][j] * u[j] for i in range(3) for j in range(3)))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    root = sys.argv[1]
    joint = parse(open(os.path.join(root, 'out', 'calibration.txtpb')).read())
    rows = []
    vertical_sigmas = []
    truth = None
    joint_truth = None  # the truth of the used sequences (one rig)
    tilt_z = []
    print('%-12s %5s %8s %8s %8s  %s' % ('sequence', 'used', 'z tilt1', 'z tilt2', 'z vert',
                                          'sigma vert [deg]'))
    for s in joint.get('sequences', []):
        name = get(s, 'name', '')
        seq_truth = os.path.join(root, name + '.truth.txtpb')
        truth = parse(open(seq_truth).read())
        cal = parse(open(os.path.join(root, 'out', name, 'calibration.txtpb')).read())
        e, _, p = errors(cal, truth)
        d = directions(truth)
        z = {k: dot(e, u) / sigma_along(p, u) for k, u in d.items()}
        used = get(s, 'used', 'false') in ('true', 1.0, True)
        if used and joint_truth is None:
            joint_truth = truth
        if used:
            tilt_z += [z['tilt_a'], z['tilt_b']]
            vertical_sigmas.append(math.degrees(sigma_along(p, d['vertical'])))
        print('%-12s %5s %+8.2f %+8.2f %+8.2f  %.4f' % (
            name, 'yes' if used else 'no', z['tilt_a'], z['tilt_b'], z['vertical'],
            math.degrees(sigma_along(p, d['vertical']))))
    e, t, p = errors(joint, joint_truth)
    d = directions(joint_truth)
    angle = math.degrees(math.sqrt(dot(e, e)))
    print('joint: rotation error %.4f deg; translation error (%s) mm' % (
        angle, ', '.join('%+.2f' % (x * 1e3) for x in t)))
    for k, u in d.items():
        print('  %-9s error %+.4f deg, sigma %.4f deg, z %+.2f' % (
            k, math.degrees(dot(e, u)), math.degrees(sigma_along(p, u)),
            dot(e, u) / sigma_along(p, u)))
    for i, axis in enumerate('xyz'):
        print('  r_%s      error %+.2f mm, sigma %.2f mm, z %+.2f' % (
            axis, t[i] * 1e3, math.sqrt(p[3 + i][3 + i]) * 1e3, t[i] / math.sqrt(p[3 + i][3 + i])))
    joint_vertical = math.degrees(sigma_along(p, d['vertical']))
    mean_single = sum(vertical_sigmas) / len(vertical_sigmas)
    print('joint sigma about the vertical %.4f deg = %.2f x the sequences\' mean %.4f deg' % (
        joint_vertical, joint_vertical / mean_single, mean_single))
    print('per-sequence tilt z-scores: mean %+.2f over %d (unbiased: within +-1)' % (
        sum(tilt_z) / len(tilt_z), len(tilt_z)))


if __name__ == '__main__':
    main()
