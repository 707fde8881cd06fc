#!/usr/bin/env python3
"""Prints the calibrator's timings, problem size and errors against the
simulator's truth (bench/calibrate/run_calibrate_bench.sh).

Usage: calibration_errors.py calibration.txtpb truth.txtpb rig.txtpb [calibrate_wall_s [sequence_s, default 60]]

Parses the protobuf text format with a small reader (no protobuf module
needed): nested messages become dicts, repeated fields lists.
"""
import math
import re
import sys

TOKEN = re.compile(r'\s*(?:(#[^\n]*)|([A-Za-z_][A-Za-z0-9_]*)\s*:?\s*(\{)|'
                   r'([A-Za-z_][A-Za-z0-9_]*)\s*:\s*("(?:[^"\\]|\\.)*"|[^\s{}]+)|(\}))')


def parse(text):
    root = {}
    stack = [root]
    pos = 0
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m or m.end() == pos:
            if text[pos:].strip() == '':
                break
            raise ValueError('cannot parse at %r' % text[pos:pos + 40])
        pos = m.end()
        if m.group(1):
            continue
        if m.group(3):
            child = {}
            stack[-1].setdefault(m.group(2), []).append(child)
            stack.append(child)
        elif m.group(6):
            stack.pop()
        else:
            value = m.group(5)
            if value.startswith('"'):
                value = value[1:-1]
            else:
                try:
                    value = float(value)
                except ValueError:
                    pass
            stack[-1].setdefault(m.group(4), []).append(value)
    return root


def get(d, path, default=0.0):
    for key in path.split('.'):
        if not isinstance(d, dict) or key not in d:
            return default
        d = d[key][0]
    return d


def vec(d, path):
    return [get(d, path + '.x'), get(d, path + '.y'), get(d, path + '.z')]


def quat(d, path):  # (w, x, y, z)
    return [get(d, path + '.w', 1.0), get(d, path + '.x'), get(d, path + '.y'), get(d, path + '.z')]


def qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return [aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw]


def angle_deg(a, b):
    c = [a[0], -a[1], -a[2], -a[3]]
    d = qmul(c, b)
    n = math.sqrt(sum(x * x for x in d))
    return math.degrees(2 * math.atan2(math.sqrt(d[1] ** 2 + d[2] ** 2 + d[3] ** 2), abs(d[0])) ) if n else 0.0


def main():
    cal = parse(open(sys.argv[1]).read())
    truth = parse(open(sys.argv[2]).read())
    rig = parse(open(sys.argv[3]).read())
    wall = float(sys.argv[4]) if len(sys.argv) > 4 else None
    duration = float(sys.argv[5]) if len(sys.argv) > 5 else 60.0  # sequence length, s
    print('calibrator phases (s):')
    for t in cal.get('timings', []):
        print('  %-22s %8.2f' % (get(t, 'phase', ''), get(t, 'seconds')))
    size = cal['problem_size'][0] if 'problem_size' in cal else {}
    print('problem size: knots %d, gyro %d, accel %d, lidar %d, ground %d residual blocks, '
          '%d free parameters' % (get(size, 'knots'), get(size, 'gyro_residuals'),
                                  get(size, 'accel_residuals'), get(size, 'lidar_residuals'),
                                  get(size, 'ground_residuals'), get(size, 'parameters')))
    print('solver: %d LM iterations, %.3f s per iteration, converged %s, termination %s' % (
        get(cal, 'solver.iterations'), get(cal, 'solver.seconds_per_iteration'),
        get(cal, 'solver.converged', False), get(cal, 'solver.termination', '')))
    if wall is not None:
        print('calibrate wall %.2f s (target <= 60 s), outer rounds %d (last moved %.4f deg, '
              '%.2f mm, %.3f ms), x_realtime %.2f (sequence %.0f s)' % (
            wall, get(cal, 'solver.outer_iterations'),
            get(cal, 'solver.last_outer_rotation_change_deg'),
            get(cal, 'solver.last_outer_translation_change_m') * 1e3,
            get(cal, 'solver.last_outer_time_offset_change_s') * 1e3,
            duration / wall if wall > 0 else 0.0, duration))
    # Normal of the plane of motion in b: gravity-up on flat ground (g_f, the
    # same on tilted ground for a rigid vehicle), else gravity at t0 (a = b(t0)).
    up = vec(truth, 'gravity_flat_in_imu')
    if not any(up):
        up = vec(truth, 'gravity_in_world')
    n = math.sqrt(sum(x * x for x in up))
    up = [-x / n for x in up]
    est_t = vec(cal, 'imu_from_lidar.translation')
    tru_t = vec(truth, 'imu_from_lidar.translation')
    rig_t = vec(rig, 'imu_from_lidar.translation')
    dt = [e - t for e, t in zip(est_t, tru_t)]
    vertical = sum(a * b for a, b in zip(dt, up))
    planar = math.sqrt(max(0.0, sum(x * x for x in dt) - vertical ** 2))
    rot = angle_deg(quat(cal, 'imu_from_lidar.rotation'), quat(truth, 'imu_from_lidar.rotation'))
    rig_rot = angle_deg(quat(rig, 'imu_from_lidar.rotation'), quat(truth, 'imu_from_lidar.rotation'))
    tau = (get(cal, 'time_offset_s') - get(truth, 'time_offset_s')) * 1e3
    print('errors vs truth (targets: rotation <= 0.1 deg, planar translation <= 1 cm, '
          'tau <= 0.5 ms):')
    print('  rotation            %.4f deg   (rig: %.3f deg)' % (rot, rig_rot))
    print('  translation b-x/y/z %.3f / %.3f / %.3f cm   (rig: %.1f / %.1f / %.1f cm)' % (
        dt[0] * 100, dt[1] * 100, dt[2] * 100, (rig_t[0] - tru_t[0]) * 100,
        (rig_t[1] - tru_t[1]) * 100, (rig_t[2] - tru_t[2]) * 100))
    print('  translation in the plane of motion %.3f cm, along its normal %.3f cm' % (
        planar * 100, vertical * 100))
    print('  tau                 %.3f ms   (truth %.2f ms)' % (tau, get(truth, 'time_offset_s') * 1e3))
    g_est = vec(cal, 'gravity_in_world')
    g_tru = vec(truth, 'gravity_in_world')
    c = sum(a * b for a, b in zip(g_est, g_tru)) / (
        math.sqrt(sum(x * x for x in g_est)) * math.sqrt(sum(x * x for x in g_tru)))
    print('  gravity direction   %.4f deg' % math.degrees(math.acos(max(-1.0, min(1.0, c)))))
    print('  sigma: rotation %.4f/%.4f/%.4f deg, translation %.2f/%.2f/%.2f mm, tau %.3f ms' % (
        get(cal, 'rotation_sigma_deg.x'), get(cal, 'rotation_sigma_deg.y'),
        get(cal, 'rotation_sigma_deg.z'), get(cal, 'translation_sigma_m.x') * 1e3,
        get(cal, 'translation_sigma_m.y') * 1e3, get(cal, 'translation_sigma_m.z') * 1e3,
        get(cal, 'time_offset_sigma_s') * 1e3))
    print('observability:')
    for d in cal.get('observability', []):
        print('  ' + get(d, 'description', ''))


if __name__ == '__main__':
    main()
