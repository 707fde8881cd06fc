#!/usr/bin/python3
"""Copies a ROS 1 bag with every sensor_msgs/PointCloud2 rewritten as a
livox_ros_driver/CustomMsg on the same topic, with the real ROS library
(Debian python3-rosbag; the message class built by genpy from the
livox_ros_driver definition text, as in write_livox_bag.py): the same
sequence as a Livox driver would have recorded it, an oracle for
tiltcal_inspect check and tiltcal_decode.

Usage: /usr/bin/python3 pointcloud2_bag_to_livox.py IN.bag OUT.bag

Per cloud: header unchanged; per point (x, y, z float32; intensity; ring
uint16; time float32, seconds after header.stamp, negative before it):
timebase = header.stamp + round(min time * 1e9) ns, offset_time =
round(time * 1e9) - round(min time * 1e9) ns, x, y, z, reflectivity =
intensity rounded and clamped to 0..255, tag 0 (a normal return), line =
ring. Every other message is copied as it is; record times are kept.
"""

import struct
import sys

import rosbag

from write_livox_bag import POINT, message_classes


def convert(cloud, Msg, Point):
    fields = {f.name: f.offset for f in cloud.fields}
    m = Msg()
    m.header = cloud.header
    m.lidar_id = 1
    m.rsvd = [0, 0, 0]
    data = bytes(cloud.data)
    endian = ">" if cloud.is_bigendian else "<"
    points = []
    for i in range(cloud.width * cloud.height):
        base = i * cloud.point_step
        x, y, z, intensity, t = (struct.unpack_from(endian + "f", data, base + fields[k])[0]
                                 for k in ("x", "y", "z", "intensity", "time"))
        ring = struct.unpack_from(endian + "H", data, base + fields["ring"])[0]
        points.append((x, y, z, intensity, int(round(t * 1e9)), ring))
    first_ns = min((p[4] for p in points), default=0)
    m.timebase = cloud.header.stamp.secs * 10**9 + cloud.header.stamp.nsecs + first_ns
    for x, y, z, intensity, t_ns, ring in points:
        p = Point()
        p.offset_time = t_ns - first_ns
        p.x, p.y, p.z = x, y, z
        p.reflectivity = max(0, min(255, int(round(intensity))))
        p.tag = 0
        p.line = ring
        m.points.append(p)
    m.point_num = len(m.points)
    return m


def main():
    source, out = sys.argv[1], sys.argv[2]
    Msg, Point = message_classes("livox_ros_driver/CustomMsg", POINT)
    with rosbag.Bag(source) as bag, rosbag.Bag(out, "w") as dest:
        for topic, msg, t in bag.read_messages(raw=True):
            if msg[0] == "sensor_msgs/PointCloud2":
                cloud = msg[4]()
                cloud.deserialize(msg[1])
                dest.write(topic, convert(cloud, Msg, Point), t)
            else:
                dest.write(topic, msg, t, raw=True)


if __name__ == "__main__":
    main()
