#!/usr/bin/python3
"""Dumps the messages of one topic of a ROS1 bag as read by the real ROS
library (Debian python3-rosbag + sensor_msgs.point_cloud2.read_points), as an
oracle for the tiltcal_decode tests.

Usage: /usr/bin/python3 rosbag_dump.py BAG TOPIC

Output, one line per item, floats as repr() (exact round trip):
  sensor_msgs/Imu:
    imu RECORD_NS STAMP_NS frame=FRAME_ID ox oy oz ow wx wy wz ax ay az
  sensor_msgs/PointCloud2:
    cloud RECORD_NS STAMP_NS frame=FRAME_ID HEIGHT WIDTH POINT_STEP ROW_STEP FIELD_NAMES(comma-separated)
    p V1 V2 ...        every point (skip_nans=False), values in FIELD_NAMES order
  other types:
    msg RECORD_NS TYPE
"""

import sys

import rosbag
import sensor_msgs.point_cloud2 as pc2


def ns(t):
    return t.secs * 1000000000 + t.nsecs


def main():
    bag_path, topic = sys.argv[1], sys.argv[2]
    out = sys.stdout
    with rosbag.Bag(bag_path) as bag:
        for _, msg, t in bag.read_messages(topics=[topic]):
            kind = msg._type
            if kind == "sensor_msgs/Imu":
                o, w, a = msg.orientation, msg.angular_velocity, msg.linear_acceleration
                values = [o.x, o.y, o.z, o.w, w.x, w.y, w.z, a.x, a.y, a.z]
                out.write("imu %d %d frame=%s %s\n" % (ns(t), ns(msg.header.stamp), msg.header.frame_id,
                                                 " ".join(repr(float(v)) for v in values)))
            elif kind == "sensor_msgs/PointCloud2":
                names = [f.name for f in msg.fields]
                out.write("cloud %d %d frame=%s %d %d %d %d %s\n" % (
                    ns(t), ns(msg.header.stamp), msg.header.frame_id, msg.height, msg.width,
                    msg.point_step, msg.row_step, ",".join(names)))
                for p in pc2.read_points(msg, field_names=names, skip_nans=False):
                    out.write("p " + " ".join(repr(v) for v in p) + "\n")
            else:
                out.write("msg %d %s\n" % (ns(t), kind))


if __name__ == "__main__":
    main()
