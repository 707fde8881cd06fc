#!/usr/bin/python3
"""Writes a ROS 1 bag of Livox CustomMsg (and sensor_msgs/Imu) with the real
ROS library (Debian python3-rosbag; the message class is built by genpy from
the livox_ros_driver definition text), as an oracle for tiltcal_decode, and
prints what it wrote.

Usage: /usr/bin/python3 write_livox_bag.py OUT.bag EXPECTED.txt
           [--type=livox_ros_driver/CustomMsg|livox_ros_driver2/CustomMsg]
           [--bad=point_num|truncated|definition]

Content (deterministic): 60 Imu on /imu (200 Hz), 4 CustomMsg on /livox/lidar
(10 Hz) of 500 points each with random coordinates, offset_time, reflectivity,
tag and line; some points are NaN, some at the origin (no return), some
tagged as noise. header.stamp = timebase, except message 2 whose timebase is
3 ms before its stamp.
--bad: message 1 is written with point_num one more than its points
(point_num), cut 7 bytes short inside its points array (truncated), or the
topic is recorded with a definition whose CustomPoint has no `line`
(definition).

EXPECTED.txt, one line per CustomMsg in record order:
  msg SEC NSEC TIMEBASE POINT_NUM LIDAR_ID FRAME
then one line per point: OFFSET_TIME X Y Z REFLECTIVITY TAG LINE, the
coordinates as the float32 written (repr of the double it converts to).
"""

import io
import random
import struct
import sys

import genpy
import genpy.dynamic
import rosbag
from sensor_msgs.msg import Imu

SEP = "=" * 80 + "\n"
HEADER = ("MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n")
POINT = ("uint32 offset_time\nfloat32 x\nfloat32 y\nfloat32 z\nuint8 reflectivity\n"
         "uint8 tag\nuint8 line\n")
POINT_WITHOUT_LINE = "uint32 offset_time\nfloat32 x\nfloat32 y\nfloat32 z\nuint8 reflectivity\nuint8 tag\n"
TOP = ("Header header\nuint64 timebase\nuint32 point_num\nuint8 lidar_id\nuint8[3] rsvd\n"
       "CustomPoint[] points\n")


def message_classes(msg_type, point_text):
    pkg = msg_type.split("/")[0]
    text = TOP + "\n" + SEP + HEADER + "\n" + SEP + "MSG: %s/CustomPoint\n" % pkg + point_text
    classes = genpy.dynamic.generate_dynamic(msg_type, text)
    return classes[msg_type], classes[pkg + "/CustomPoint"]


def f32(v):
    return struct.unpack("<f", struct.pack("<f", v))[0]


def main():
    out, expected = sys.argv[1], sys.argv[2]
    msg_type = "livox_ros_driver/CustomMsg"
    bad = ""
    for a in sys.argv[3:]:
        if a.startswith("--type="):
            msg_type = a[7:]
        elif a.startswith("--bad="):
            bad = a[6:]
        else:
            raise SystemExit("unknown argument " + a)
    Msg, Point = message_classes(msg_type,
                                 POINT_WITHOUT_LINE if bad == "definition" else POINT)
    rng = random.Random(360)
    t0 = 1700000000 * 10**9
    with rosbag.Bag(out, "w") as bag, open(expected, "w") as exp:
        messages = []
        for i in range(60):
            ns = t0 + i * 5000000
            imu = Imu()
            imu.header.seq = i
            imu.header.stamp = genpy.Time(ns // 10**9, ns % 10**9)
            imu.header.frame_id = "livox_imu"
            imu.angular_velocity.x = rng.uniform(-1, 1)
            imu.linear_acceleration.z = rng.uniform(0.95, 1.05)  # in g, as the Livox IMU
            messages.append((ns + 100000, "/imu", imu))
        for k in range(4):
            stamp = t0 + 20000000 + k * 100000000
            timebase = stamp - (3000000 if k == 2 else 0)
            m = Msg()
            m.header.seq = k
            m.header.stamp = genpy.Time(stamp // 10**9, stamp % 10**9)
            m.header.frame_id = "livox_frame"
            m.timebase = timebase
            m.lidar_id = 1 + k
            m.rsvd = [0, 0, 0]
            for j in range(500):
                p = Point()
                p.offset_time = j * 200000 + rng.randrange(0, 1000)
                r = rng.random()
                if r < 0.05:
                    p.x, p.y, p.z = float("nan"), rng.uniform(-5, 5), 1.0
                elif r < 0.15:
                    p.x = p.y = p.z = 0.0
                else:
                    p.x, p.y, p.z = (f32(rng.uniform(-40, 40)) for _ in range(3))
                p.reflectivity = rng.randrange(0, 256)
                p.tag = rng.choice([0x00, 0x00, 0x00, 0x10, 0x20, 0x01, 0x02, 0x03, 0x04, 0x08])
                if bad != "definition":
                    p.line = rng.randrange(0, 6)
                m.points.append(p)
            m.point_num = len(m.points) + (1 if bad == "point_num" and k == 1 else 0)
            messages.append((stamp + 30000000, "/livox/lidar", m))
        messages.sort(key=lambda x: x[0])
        for record_ns, topic, m in messages:
            t = genpy.Time(record_ns // 10**9, record_ns % 10**9)
            if topic == "/livox/lidar" and bad == "truncated" and m.header.seq == 1:
                buf = io.BytesIO()
                m.serialize(buf)
                data = buf.getvalue()[:-7]
                bag.write(topic, (m._type, data, m._md5sum, Msg), t, raw=True)
            else:
                bag.write(topic, m, t)
            if topic != "/livox/lidar":
                continue
            s = m.header.stamp
            exp.write("msg %d %d %d %d %d %s\n" % (s.secs, s.nsecs, m.timebase, m.point_num,
                                                  m.lidar_id, m.header.frame_id))
            for p in m.points:
                exp.write("%d %r %r %r %d %d %d\n" % (p.offset_time, p.x, p.y, p.z,
                                                      p.reflectivity, p.tag,
                                                      getattr(p, "line", 0)))


if __name__ == "__main__":
    main()
