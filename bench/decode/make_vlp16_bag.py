#!/usr/bin/python3
"""Writes a large lz4-compressed ROS1 bag of VLP-16-like clouds plus a 200 Hz IMU.

Benchmark input for bench/decode/run_decode_bench.sh; not a test fixture.
Uses Debian's python3-rosbag and python3-sensor-msgs (hence /usr/bin/python3).

Contents
  /velodyne_points  sensor_msgs/PointCloud2 at 10 Hz, frame "velodyne", in the
                    layout of the ros-drivers/velodyne driver's own cloud
                    (pointcloudXYZIRT): x, y, z, intensity FLOAT32 @0/4/8/12,
                    ring UINT16 @16, time FLOAT32 @18, point_step 22, height 1,
                    points in firing order (16 lasers per firing, interleaved
                    vertical angles), `time` in seconds relative to the stamp of
                    the LAST packet (so in [-0.1, 0)), is_dense 1.
  /imu/data         sensor_msgs/Imu at 200 Hz, frame "imu_link".

Geometry: a VLP-16 (vertical angles -15..15 deg in 2 deg steps, 0.2 deg
azimuth step at 600 rpm -> 1800 firings x 16 = 28,800 rays) mounted 1.8 m above
a flat road in a street canyon: facades on both sides with a set-back that
changes every 8 m, poles, parked cars (boxes) and far end walls, so that every
ray returns. Ranges are quantised to 2 mm like the sensor's raw returns.
About 1 % of the rays drop out at random per scan (width ~28,500).

Speed: a few base scans (vehicle positions along the street) are ray-cast once
with numpy; every message re-uses one of them with fresh range noise
(sigma 1 cm), fresh intensity noise and a fresh drop-out mask, so no two
clouds are byte-identical and lz4 sees realistic float data.

The bag is written until the file reaches --size_gb * 1e9 bytes (record time
starts at --start_s). Existing output is replaced atomically (written to
OUT.partial.PID, then renamed); OUT.meta gets bytes, clouds, points, imu counts.
"""

import argparse
import math
import os
import sys
import time

import numpy as np
import rosbag
import rospy
from sensor_msgs.msg import Imu, PointCloud2, PointField

NUM_LASERS = 16
NUM_FIRINGS = 1800                    # 360 deg / 0.2 deg
SCAN_PERIOD_S = 0.1                   # 10 Hz
FIRING_SEQUENCE_S = 55.296e-6         # VLP-16 firing sequence (16 lasers + recharge)
FIRING_S = 2.304e-6                   # one laser firing
SENSOR_HEIGHT_M = 1.8
SPEED_MPS = 5.0
IMU_RATE_HZ = 200
NUM_BASE_SCANS = 8

# Laser id j -> vertical angle, in firing order (VLP-16 manual): -15, 1, -13, 3, ...
VERTICAL_DEG = np.array([-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15],
                        dtype=np.float64)
# ring = index of the laser sorted by increasing vertical angle (driver calibration.cc).
RING = np.argsort(np.argsort(VERTICAL_DEG)).astype(np.uint16)

POINT_DTYPE = np.dtype({
    'names': ['x', 'y', 'z', 'intensity', 'ring', 'time'],
    'formats': ['<f4', '<f4', '<f4', '<f4', '<u2', '<f4'],
    'offsets': [0, 4, 8, 12, 16, 18],
    'itemsize': 22,
})


def point_fields():
    f = []
    for name, offset, datatype in [('x', 0, PointField.FLOAT32), ('y', 4, PointField.FLOAT32),
                                   ('z', 8, PointField.FLOAT32),
                                   ('intensity', 12, PointField.FLOAT32),
                                   ('ring', 16, PointField.UINT16),
                                   ('time', 18, PointField.FLOAT32)]:
        f.append(PointField(name=name, offset=offset, datatype=datatype, count=1))
    return f


def ray_directions():
    """Unit ray directions (N,3) in the LiDAR frame, firing-major order, and
    per-ray laser index, firing index."""
    firing = np.repeat(np.arange(NUM_FIRINGS), NUM_LASERS)
    laser = np.tile(np.arange(NUM_LASERS), NUM_FIRINGS)
    # Azimuth advances during the firing sequence (0.2 deg per sequence).
    azimuth = np.deg2rad(firing * 0.2 + laser * (0.2 * FIRING_S / FIRING_SEQUENCE_S))
    elevation = np.deg2rad(VERTICAL_DEG[laser])
    d = np.stack([np.cos(elevation) * np.cos(azimuth),
                  -np.cos(elevation) * np.sin(azimuth),  # clockwise rotation
                  np.sin(elevation)], axis=1)
    return d, laser, firing


class Street:
    """Street canyon along x; the vehicle drives along y = 0."""

    def __init__(self, rng):
        self.segment_m = 8.0
        self.num_segments = 64                      # street from x = -256 to 256 m
        self.x0 = -self.segment_m * self.num_segments / 2
        self.left = rng.uniform(6.0, 14.0, self.num_segments)    # facade at y = +left
        self.right = rng.uniform(6.0, 14.0, self.num_segments)   # facade at y = -right
        self.poles = np.stack([np.arange(-250, 250, 17.0) + rng.uniform(-2, 2, 30),
                               rng.choice([-1, 1], 30) * rng.uniform(4.5, 5.5, 30)], axis=1)
        n_cars = 40
        cx = rng.uniform(-250, 250, n_cars)
        cy = rng.choice([-1, 1], n_cars) * 3.5
        self.cars = [(x - 2.2, x + 2.2, y - 0.9, y + 0.9, -SENSOR_HEIGHT_M, -SENSOR_HEIGHT_M + 1.5)
                     for x, y in zip(cx, cy)]
        # Cross streets' far facades ahead of and behind the vehicle (T-junctions).
        self.end_ahead_m = 72.0
        self.end_behind_m = 55.0

    def cast(self, origin, d):
        """Range (N,) and surface class (N,) of rays from origin along d."""
        n = d.shape[0]
        best = np.full(n, np.inf)
        cls = np.zeros(n, dtype=np.int8)
        ox, oy, oz = origin
        dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
        with np.errstate(divide='ignore', invalid='ignore'):
            # Ground z = -SENSOR_HEIGHT_M.
            t = np.where(dz < 0, (-SENSOR_HEIGHT_M - oz) / dz, np.inf)
            better = t < best
            best[better] = t[better]
            cls[better] = 1
            # Facades, one plane per segment and side.
            for side, setbacks in ((1.0, self.left), (-1.0, self.right)):
                for k, w in enumerate(setbacks):
                    t = (side * w - oy) / dy
                    hx = ox + t * dx
                    lo = self.x0 + k * self.segment_m
                    ok = (t > 0) & (hx >= lo) & (hx < lo + self.segment_m)
                    t = np.where(ok, t, np.inf)
                    better = t < best
                    best[better] = t[better]
                    cls[better] = 2
                # Side walls between segments of different set-back (planes x = const).
                for k in range(1, len(setbacks)):
                    xk = self.x0 + k * self.segment_m
                    t = (xk - ox) / dx
                    hy = oy + t * dy
                    a, b = sorted((setbacks[k - 1], setbacks[k]))
                    ok = (t > 0) & (side * hy >= a) & (side * hy <= b)
                    t = np.where(ok, t, np.inf)
                    better = t < best
                    best[better] = t[better]
                    cls[better] = 2
            # End walls.
            for xe in (ox - self.end_behind_m, ox + self.end_ahead_m):
                t = (xe - ox) / dx
                t = np.where(t > 0, t, np.inf)
                better = t < best
                best[better] = t[better]
                cls[better] = 2
            # Poles: vertical cylinders r = 0.12 m, 6 m tall.
            a = dx * dx + dy * dy
            for px, py in self.poles:
                fx, fy = ox - px, oy - py
                b = 2 * (fx * dx + fy * dy)
                c = fx * fx + fy * fy - 0.12 ** 2
                disc = b * b - 4 * a * c
                t = np.where(disc >= 0, (-b - np.sqrt(np.maximum(disc, 0))) / (2 * a), np.inf)
                hz = oz + t * dz
                ok = (t > 0) & (hz < -SENSOR_HEIGHT_M + 6.0)
                t = np.where(ok, t, np.inf)
                better = t < best
                best[better] = t[better]
                cls[better] = 3
            # Cars: axis-aligned boxes (slab test).
            inv = 1.0 / d
            for x0, x1, y0, y1, z0, z1 in self.cars:
                tx0, tx1 = (x0 - ox) * inv[:, 0], (x1 - ox) * inv[:, 0]
                ty0, ty1 = (y0 - oy) * inv[:, 1], (y1 - oy) * inv[:, 1]
                tz0, tz1 = (z0 - oz) * inv[:, 2], (z1 - oz) * inv[:, 2]
                tmin = np.maximum.reduce([np.minimum(tx0, tx1), np.minimum(ty0, ty1),
                                          np.minimum(tz0, tz1)])
                tmax = np.minimum.reduce([np.maximum(tx0, tx1), np.maximum(ty0, ty1),
                                          np.maximum(tz0, tz1)])
                ok = (tmax >= tmin) & (tmin > 0)
                t = np.where(ok, tmin, np.inf)
                better = t < best
                best[better] = t[better]
                cls[better] = 4
        best[~np.isfinite(best)] = 100.0  # never reached: the canyon is closed
        return best, cls


def make_base_scans(rng):
    d, laser, firing = ray_directions()
    street = Street(rng)
    scans = []
    for k in range(NUM_BASE_SCANS):
        origin = (-120.0 + k * 31.0, rng.uniform(-0.5, 0.5), 0.0)
        r, cls = street.cast(origin, d)
        base_intensity = np.choose(cls, [5.0, 18.0, 45.0, 120.0, 80.0])
        # Lane markings: bright stripes on the ground at |y| ~ 0 and 3.5 m.
        hit_y = origin[1] + r * d[:, 1]
        marking = (cls == 1) & ((np.abs(hit_y) < 0.08) | (np.abs(np.abs(hit_y) - 3.5) < 0.08))
        base_intensity = np.where(marking, 200.0, base_intensity)
        scans.append((r, base_intensity))
    # time: relative to the last packet (driver default timestamp_first_packet=false).
    t = (firing * FIRING_SEQUENCE_S + laser * FIRING_S) - NUM_FIRINGS * FIRING_SEQUENCE_S
    return d, RING[laser], t.astype(np.float32), scans


def imu_message(stamp, seq, rng):
    msg = Imu()
    msg.header.seq = seq
    msg.header.stamp = stamp
    msg.header.frame_id = 'imu_link'
    t = stamp.to_sec()
    yaw = 0.05 * math.sin(0.3 * t)
    roll = 0.01 * math.sin(1.7 * t)
    pitch = 0.015 * math.sin(1.1 * t)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    msg.orientation.w = cr * cp * cy + sr * sp * sy
    msg.orientation.x = sr * cp * cy - cr * sp * sy
    msg.orientation.y = cr * sp * cy + sr * cp * sy
    msg.orientation.z = cr * cp * sy - sr * sp * cy
    noise = rng.normal(0.0, 1.0, 6)
    msg.angular_velocity.x = 0.017 * math.cos(1.7 * t) + 0.002 * noise[0]
    msg.angular_velocity.y = 0.0165 * math.cos(1.1 * t) + 0.002 * noise[1]
    msg.angular_velocity.z = 0.015 * math.cos(0.3 * t) + 0.002 * noise[2]
    msg.linear_acceleration.x = 0.3 * math.sin(0.5 * t) + 0.02 * noise[3]
    msg.linear_acceleration.y = 0.1 * math.sin(0.9 * t) + 0.02 * noise[4]
    msg.linear_acceleration.z = 9.80665 + 0.02 * noise[5]
    msg.orientation_covariance = [1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4]
    msg.angular_velocity_covariance = [4e-6, 0, 0, 0, 4e-6, 0, 0, 0, 4e-6]
    msg.linear_acceleration_covariance = [4e-4, 0, 0, 0, 4e-4, 0, 0, 0, 4e-4]
    return msg


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--out', required=True, help='output .bag path')
    parser.add_argument('--size_gb', type=float, default=1.0,
                        help='stop once the bag file has at least this many 1e9 bytes')
    parser.add_argument('--compression', default='lz4', choices=['lz4', 'bz2', 'none'])
    parser.add_argument('--start_s', type=float, default=1700000000.0,
                        help='record time of the first message, s since epoch')
    parser.add_argument('--seed', type=int, default=7)
    args = parser.parse_args()

    rng = np.random.default_rng(args.seed)
    wall0 = time.time()
    d, ring, point_time, scans = make_base_scans(rng)
    num_rays = d.shape[0]
    points = np.zeros(num_rays, dtype=POINT_DTYPE)
    points['ring'] = ring
    points['time'] = point_time
    fields = point_fields()
    target_bytes = int(args.size_gb * 1e9)
    partial = '%s.partial.%d' % (args.out, os.getpid())  # private to this process
    for stale in (partial, args.out + '.meta'):
        if os.path.exists(stale):
            os.remove(stale)

    num_scans = 0
    num_imu = 0
    num_points = 0
    imu_period_s = 1.0 / IMU_RATE_HZ
    imu_per_scan = int(round(SCAN_PERIOD_S * IMU_RATE_HZ))
    with rosbag.Bag(partial, 'w', compression=args.compression) as bag:
        while True:
            scan_end_s = args.start_s + (num_scans + 1) * SCAN_PERIOD_S
            # IMU samples of this scan period, then the cloud (published ~10 ms
            # after the last packet, so record time is later than the stamp).
            for i in range(imu_per_scan):
                stamp_s = scan_end_s - SCAN_PERIOD_S + (i + 1) * imu_period_s
                stamp = rospy.Time.from_sec(stamp_s)
                bag.write('/imu/data', imu_message(stamp, num_imu, rng),
                          t=rospy.Time.from_sec(stamp_s + 0.001))
                num_imu += 1
            r, base_intensity = scans[num_scans % NUM_BASE_SCANS]
            noisy_r = np.round((r + rng.normal(0.0, 0.01, num_rays)) / 0.002) * 0.002
            xyz = d * noisy_r[:, None]
            points['x'] = xyz[:, 0]
            points['y'] = xyz[:, 1]
            points['z'] = xyz[:, 2]
            points['intensity'] = np.clip(
                np.round(base_intensity + rng.normal(0.0, 3.0, num_rays)), 0, 255)
            keep = rng.random(num_rays) >= 0.01
            cloud = points[keep]
            msg = PointCloud2()
            msg.header.seq = num_scans
            msg.header.stamp = rospy.Time.from_sec(scan_end_s)
            msg.header.frame_id = 'velodyne'
            msg.height = 1
            msg.width = cloud.shape[0]
            msg.fields = fields
            msg.is_bigendian = False
            msg.point_step = POINT_DTYPE.itemsize
            msg.row_step = msg.point_step * msg.width
            msg.data = cloud.tobytes()
            msg.is_dense = True
            bag.write('/velodyne_points', msg, t=rospy.Time.from_sec(scan_end_s + 0.010))
            num_scans += 1
            num_points += msg.width
            if num_scans % 200 == 0:
                size = os.path.getsize(partial)
                print('make_vlp16_bag: %d scans, %.2f GB, %.0f s' %
                      (num_scans, size / 1e9, time.time() - wall0), file=sys.stderr)
                if size >= target_bytes:
                    break
            elif num_scans % 20 == 0 and os.path.getsize(partial) >= target_bytes:
                break
    os.replace(partial, args.out)
    size = os.path.getsize(args.out)
    # Sidecar with the bag's contents, read by run_decode_bench.sh.
    meta_tmp = '%s.meta.tmp.%d' % (args.out, os.getpid())
    with open(meta_tmp, 'w') as meta:
        meta.write('bytes=%d\nclouds=%d\npoints=%d\nimu=%d\ncompression=%s\n' %
                   (size, num_scans, num_points, num_imu, args.compression))
    os.replace(meta_tmp, args.out + '.meta')
    print('make_vlp16_bag: wrote %s: %d bytes, %d clouds, %d points, %d imu messages, '
          '%.1f s of data, %.0f s' % (args.out, size, num_scans, num_points, num_imu,
                                      num_scans * SCAN_PERIOD_S, time.time() - wall0),
          file=sys.stderr)


if __name__ == '__main__':
    main()
