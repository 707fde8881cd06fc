#!/usr/bin/python3
"""Writes ROS1 test bags with Debian's real rosbag library, plus the values
written, so that tiltcal_decode can be checked against what went in.

Usage: /usr/bin/python3 write_test_bags.py OUT_DIR

Bags (each with /imu/data sensor_msgs/Imu and /points sensor_msgs/PointCloud2):
  {velodyne,ouster,hesai}_{none,bz2,lz4}.bag   small chunk_threshold: several chunks
    velodyne: point_step 22 (x y z intensity FLOAT32, ring UINT16 @16,
              time FLOAT32 @18 s relative to the stamp, negative), height 1
    ouster:   point_step 48, organized 16 x 64 with padded rows, NaN pixels,
              t UINT32 @20 ns relative, ring UINT8 @26, reflectivity UINT16 @24
    hesai:    point_step 26 (ring UINT16 @16, timestamp FLOAT64 @18 absolute s)
  unindexed.bag   velodyne clouds, compression none, written without close():
                  closed chunks followed by an open one (salvage case)
  imu_only.bag    no PointCloud2 at all
  truncated_message.bag  a valid bag whose Imu message 3 lacks its last 8 bytes
  two_imus.bag    Imu on /imu/a (20 msgs) and /imu/b (30 msgs), clouds on /points
Expected values: {kind}_expected.txt / unindexed_expected.txt, one line per
message in write order:
  imu  RECORD_NS STAMP_NS wx wy wz ax ay az
  scan RECORD_NS STAMP_NS FRAME_ID TIME_SOURCE NUM_INVALID NUM_BELOW_MIN_RANGE NUM_KEPT
  p    x y z intensity ring time_offset_ns          (kept points, in cloud order)
Points are dropped when a coordinate is NaN/Inf or the range is below
MIN_RANGE_M (0.5 m, the value the tests use). Floats are written with repr()
of the float32 / float64 value actually stored in the bag.
"""

import io
import math
import os
import random
import struct
import sys
from fractions import Fraction

import genpy
import rosbag
from sensor_msgs.msg import Imu, PointCloud2, PointField

MIN_RANGE_M = 0.5
BASE_SEC = 1700000000
IMU_TOPIC = "/imu/data"
LIDAR_TOPIC = "/points"

# time_source enum values of tiltcal.proto.PointTimeSource
VELODYNE_TIME, OUSTER_T, ABSOLUTE_SECONDS = 1, 2, 3


def f32(v):
    return struct.unpack("<f", struct.pack("<f", v))[0]


def round_half_away(x):
    # Exact for Fraction and float; ties away from zero like C llround.
    if x >= 0:
        return int(math.floor(x + Fraction(1, 2)))
    return -int(math.floor(-x + Fraction(1, 2)))


def rtime(ns):
    return genpy.Time(ns // 1000000000, ns % 1000000000)


def make_imu(rng, stamp_ns):
    msg = Imu()
    msg.header.stamp = rtime(stamp_ns)
    msg.header.frame_id = "imu_link"
    msg.orientation.w = 1.0
    w = [rng.uniform(-2, 2) for _ in range(3)]
    # Specific force of an IMU that is roughly level and z-up (|f| near 9.81):
    # the decode stage checks the accelerometer's unit and sign on it.
    a = [rng.uniform(-2, 2), rng.uniform(-2, 2), 9.81 + rng.uniform(-2, 2)]
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = w
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = a
    msg.orientation_covariance[0] = -1.0
    return msg, w + a


def random_point(rng):
    """A float32 point; sometimes invalid, at zero or below the minimum range."""
    u = rng.random()
    if u < 0.03:
        return (float("nan"), f32(rng.uniform(-5, 5)), f32(1.0))
    if u < 0.05:
        return (0.0, 0.0, 0.0)
    if u < 0.08:
        return (f32(0.2), f32(-0.1), f32(0.05))  # 0.23 m: below the minimum range
    if u < 0.09:
        return (float("inf"), 0.0, 0.0)
    r = rng.uniform(1.0, 60.0)
    az = rng.uniform(-math.pi, math.pi)
    el = rng.uniform(-0.3, 0.3)
    return (f32(r * math.cos(el) * math.cos(az)), f32(r * math.cos(el) * math.sin(az)),
            f32(r * math.sin(el)))


def keep(p):
    if not all(math.isfinite(v) for v in p):
        return "invalid"
    r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
    if r2 == 0.0 or r2 < MIN_RANGE_M * MIN_RANGE_M:
        return "range"
    return "kept"


def field(name, offset, datatype):
    return PointField(name=name, offset=offset, datatype=datatype, count=1)


def make_cloud(kind, rng, stamp_ns):
    """Returns (PointCloud2, time_source, kept point tuples, n_invalid, n_range)."""
    msg = PointCloud2()
    msg.header.stamp = rtime(stamp_ns)
    msg.is_bigendian = False
    kept, n_invalid, n_range = [], 0, 0
    sec, nsec = stamp_ns // 1000000000, stamp_ns % 1000000000
    if kind == "velodyne":
        msg.header.frame_id = "velodyne"
        msg.fields = [field("x", 0, 7), field("y", 4, 7), field("z", 8, 7),
                      field("intensity", 12, 7), field("ring", 16, 4), field("time", 18, 7)]
        msg.point_step, msg.height, msg.width = 22, 1, 16 * 60
        msg.row_step = msg.point_step * msg.width
        data = bytearray()
        for col in range(60):
            for ring in range(16):
                p = random_point(rng)
                inten = f32(rng.uniform(0, 255))
                t = f32(-0.1 + col * (0.1 / 60) + ring * 2.3e-6)  # s, relative, negative
                data += struct.pack("<ffffHf", p[0], p[1], p[2], inten, ring, t)
                k = keep(p)
                if k == "kept":
                    kept.append((p[0], p[1], p[2], inten, ring, round_half_away(t * 1e9)))
                elif k == "invalid":
                    n_invalid += 1
                else:
                    n_range += 1
        msg.data = bytes(data)
        source = VELODYNE_TIME
    elif kind == "ouster":
        msg.header.frame_id = "os_sensor"
        msg.fields = [field("x", 0, 7), field("y", 4, 7), field("z", 8, 7),
                      field("intensity", 16, 7), field("t", 20, 6),
                      field("reflectivity", 24, 4), field("ring", 26, 2),
                      field("ambient", 28, 4), field("range", 32, 6)]
        msg.point_step, msg.height, msg.width = 48, 16, 64
        msg.row_step = msg.point_step * msg.width + 16  # padded rows
        data = bytearray()
        for ring in range(msg.height):
            row = bytearray()
            for col in range(msg.width):
                if rng.random() < 0.1:  # no return: NaN pixel
                    p = (float("nan"), float("nan"), float("nan"))
                else:
                    p = random_point(rng)
                inten = f32(rng.uniform(0, 3000))
                t = col * 1562500 + ring * 7  # ns after the stamp
                pt = bytearray(48)
                struct.pack_into("<fff", pt, 0, *p)
                struct.pack_into("<fIHBxHxxI", pt, 16, inten, t, 77, ring, 123, 4567)
                row += pt
                k = keep(p)
                if k == "kept":
                    kept.append((p[0], p[1], p[2], inten, ring, t))
                elif k == "invalid":
                    n_invalid += 1
                else:
                    n_range += 1
            data += row + bytes(16)
        msg.data = bytes(data)
        source = OUSTER_T
    else:  # hesai
        msg.header.frame_id = "hesai_lidar"
        msg.fields = [field("x", 0, 7), field("y", 4, 7), field("z", 8, 7),
                      field("intensity", 12, 7), field("ring", 16, 4),
                      field("timestamp", 18, 8)]
        msg.point_step, msg.height, msg.width = 26, 1, 32 * 30
        msg.row_step = msg.point_step * msg.width
        data = bytearray()
        for col in range(30):
            for ring in range(32):
                p = random_point(rng)
                inten = f32(rng.uniform(0, 255))
                offset_us = col * 3333 + ring * 3
                ts = (stamp_ns + offset_us * 1000) / 1e9  # absolute s, float64
                data += struct.pack("<ffffHd", p[0], p[1], p[2], inten, ring, ts)
                k = keep(p)
                if k == "kept":
                    exact = Fraction(ts) * 1000000000 - stamp_ns
                    kept.append((p[0], p[1], p[2], inten, ring, round_half_away(exact)))
                elif k == "invalid":
                    n_invalid += 1
                else:
                    n_range += 1
        msg.data = bytes(data)
        source = ABSOLUTE_SECONDS
    msg.is_dense = False
    return msg, source, kept, n_invalid, n_range


def write_bag(path, kind, compression, chunk_threshold, seed, lines, close=True,
              with_lidar=True, duration_s=1.0):
    rng = random.Random(seed)
    bag = rosbag.Bag(path, "w", compression=compression, chunk_threshold=chunk_threshold)
    t0 = (BASE_SEC + 12) * 1000000000 + 345678901
    # Messages in record-time order, as a recorder writes them.
    events = []
    n_imu = int(200 * duration_s)
    for i in range(n_imu):
        stamp = t0 + i * 5000000
        record = stamp + 2000000
        if i == 50:  # late sample: stamp order differs from record order
            record += 12000000
        events.append((record, "imu", stamp))
        if i == 120:  # exact duplicate published twice
            events.append((record + 100000, "imu_dup", stamp))
    if with_lidar:
        for k in range(int(10 * duration_s)):
            stamp = t0 + 3000000 + k * 100000000
            record = stamp + 50000000
            if k == 6:  # stamp jumps back, record time does not: a non-monotonic scan
                stamp -= 150000000
            events.append((record, "scan", stamp))
    events.sort(key=lambda e: e[0])
    last_imu = None
    for record, what, stamp in events:
        if what == "imu":
            msg, values = make_imu(rng, stamp)
            last_imu = (msg, values)
            bag.write(IMU_TOPIC, msg, t=rtime(record))
            lines.append("imu %d %d %s" % (record, stamp, " ".join(repr(v) for v in values)))
        elif what == "imu_dup":
            # The same stamp and values as the sample of stamp `stamp`.
            values = None
            for line in lines:
                parts = line.split()
                if parts[0] == "imu" and int(parts[2]) == stamp:
                    values = [float(v) for v in parts[3:]]
            msg = Imu()
            msg.header.stamp = rtime(stamp)
            msg.header.frame_id = "imu_link"
            msg.orientation.w = 1.0
            (msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z,
             msg.linear_acceleration.x, msg.linear_acceleration.y,
             msg.linear_acceleration.z) = values
            bag.write(IMU_TOPIC, msg, t=rtime(record))
            lines.append("imu %d %d %s" % (record, stamp, " ".join(repr(v) for v in values)))
        else:
            msg, source, kept, n_invalid, n_range = make_cloud(kind, rng, stamp)
            bag.write(LIDAR_TOPIC, msg, t=rtime(record))
            lines.append("scan %d %d %s %d %d %d %d" % (record, stamp, msg.header.frame_id, source,
                                                       n_invalid, n_range, len(kept)))
            for p in kept:
                lines.append("p %r %r %r %r %d %d" % p)
    if close:
        bag.close()
    else:
        bag._file.flush()  # leave the bag as an interrupted recording leaves it


def write_truncated_message_bag(path):
    rng = random.Random(11)
    t0 = (BASE_SEC + 50) * 1000000000
    with rosbag.Bag(path, "w") as bag:
        for i in range(6):
            stamp = t0 + i * 5000000
            msg, _ = make_imu(rng, stamp)
            if i == 3:
                buf = io.BytesIO()
                msg.serialize(buf)
                raw = ("sensor_msgs/Imu", buf.getvalue()[:-8], Imu._md5sum, Imu)
                bag.write(IMU_TOPIC, raw, t=rtime(stamp), raw=True)
            else:
                bag.write(IMU_TOPIC, msg, t=rtime(stamp))
            if i % 2 == 0:
                cloud = make_cloud("velodyne", rng, stamp)[0]
                bag.write(LIDAR_TOPIC, cloud, t=rtime(stamp + 1000))


def write_two_imus_bag(path):
    rng = random.Random(12)
    t0 = (BASE_SEC + 80) * 1000000000
    with rosbag.Bag(path, "w", compression="lz4") as bag:
        for i in range(30):
            stamp = t0 + i * 10000000
            if i < 20:
                bag.write("/imu/a", make_imu(rng, stamp)[0], t=rtime(stamp))
            bag.write("/imu/b", make_imu(rng, stamp + 1)[0], t=rtime(stamp + 1))
            if i % 10 == 0:
                bag.write(LIDAR_TOPIC, make_cloud("ouster", rng, stamp)[0], t=rtime(stamp + 2))


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for seed, kind in enumerate(["velodyne", "ouster", "hesai"]):
        lines = None
        for compression in ["none", "bz2", "lz4"]:
            current = []
            write_bag(os.path.join(out, "%s_%s.bag" % (kind, compression)), kind, compression,
                      48 * 1024, seed + 1, current)
            if lines is None:
                lines = current
            assert lines == current
        with open(os.path.join(out, "%s_expected.txt" % kind), "w") as f:
            f.write("\n".join(lines) + "\n")
    lines = []
    write_bag(os.path.join(out, "imu_only.bag"), "velodyne", "none", 48 * 1024, 7, lines,
              with_lidar=False)
    write_truncated_message_bag(os.path.join(out, "truncated_message.bag"))
    write_two_imus_bag(os.path.join(out, "two_imus.bag"))
    # Last: the unindexed bag; the process ends without closing it.
    lines = []
    path = os.path.join(out, "unindexed.bag")
    write_bag(path, "velodyne", "none", 64 * 1024, 9, lines, close=False)
    with open(os.path.join(out, "unindexed_expected.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")
    sys.stdout.flush()
    os._exit(0)


if __name__ == "__main__":
    main()
