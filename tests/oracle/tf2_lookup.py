#!/usr/bin/python3
"""Looks up a transform between two frames of a ROS1 bag's /tf_static with
the real ROS libraries (Debian python3-rosbag reads the bag, python3-tf2's
BufferCore holds the static transforms and walks the tree), as an oracle
for the tf_static tests of tiltcal_decode.

Usage: /usr/bin/python3 tf2_lookup.py BAG TARGET_FRAME SOURCE_FRAME

Prints "tx ty tz qx qy qz qw" (repr floats) of target_from_source, the
pose of SOURCE in TARGET (p_target = R p_source + t), or "none" when no
chain joins the frames.
"""

import sys

import genpy
import rosbag
import tf2_py
from geometry_msgs.msg import TransformStamped


def main():
    bag_path, target, source = sys.argv[1], sys.argv[2].lstrip("/"), sys.argv[3].lstrip("/")
    buffer = tf2_py.BufferCore()
    with rosbag.Bag(bag_path) as bag:
        for _, msg, _ in bag.read_messages(topics=["/tf_static"]):
            for recorded in msg.transforms:
                # The bag's classes are generated from its connection
                # records; tf2 takes geometry_msgs' own.
                t = TransformStamped()
                t.header.stamp = recorded.header.stamp
                t.header.frame_id = recorded.header.frame_id.lstrip("/")
                t.child_frame_id = recorded.child_frame_id.lstrip("/")
                for axis in "xyz":
                    setattr(t.transform.translation, axis,
                            getattr(recorded.transform.translation, axis))
                for axis in "xyzw":
                    setattr(t.transform.rotation, axis, getattr(recorded.transform.rotation, axis))
                buffer.set_transform_static(t, "tf2_lookup.py")
    try:
        result = buffer.lookup_transform_core(target, source, genpy.Time(0))
    except (tf2_py.LookupException, tf2_py.ConnectivityException):
        print("none")
        return
    tr, q = result.transform.translation, result.transform.rotation
    print(" ".join(repr(float(v)) for v in (tr.x, tr.y, tr.z, q.x, q.y, q.z, q.w)))


if __name__ == "__main__":
    main()
