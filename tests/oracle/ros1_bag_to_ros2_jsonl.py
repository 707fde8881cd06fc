#!/usr/bin/python3
"""Reads the sensor_msgs/Imu, sensor_msgs/PointCloud2, Livox CustomMsg and tf2_msgs/TFMessage messages of a ROS1
bag with the real ROS library (Debian python3-rosbag) and prints them as the
JSON lines write_ros2_bags.mjs --messages= takes, in record order: the same
values as ROS 2 messages (std_msgs/Header without seq, stamp as
{sec, nanosec}, the cloud's data in base64, the Livox points in base64 of
their ROS 1 wire form). Other topics are left out.

Usage: /usr/bin/python3 ros1_bag_to_ros2_jsonl.py BAG [--livox_type=TYPE] > messages.jsonl
"""

import base64
import json
import struct
import sys

import rosbag


def header(h):
    return {"stamp": {"sec": h.stamp.secs, "nanosec": h.stamp.nsecs}, "frame_id": h.frame_id}


def vector(v):
    return {"x": v.x, "y": v.y, "z": v.z}


def main():
    out = sys.stdout
    # The ROS 2 type of Livox CustomMsg (--livox_type=livox_interfaces/msg/CustomMsg).
    livox_type = "livox_ros_driver2/msg/CustomMsg"
    for a in sys.argv[2:]:
        if a.startswith("--livox_type="):
            livox_type = a[13:]
    with rosbag.Bag(sys.argv[1]) as bag:
        for topic, msg, t in bag.read_messages():
            record_ns = str(t.secs * 1000000000 + t.nsecs)
            if msg._type == "sensor_msgs/Imu":
                o = msg.orientation
                ros2 = {
                    "header": header(msg.header),
                    "orientation": {"x": o.x, "y": o.y, "z": o.z, "w": o.w},
                    "orientation_covariance": list(msg.orientation_covariance),
                    "angular_velocity": vector(msg.angular_velocity),
                    "angular_velocity_covariance": list(msg.angular_velocity_covariance),
                    "linear_acceleration": vector(msg.linear_acceleration),
                    "linear_acceleration_covariance": list(msg.linear_acceleration_covariance),
                }
                kind = "sensor_msgs/msg/Imu"
            elif msg._type == "sensor_msgs/PointCloud2":
                ros2 = {
                    "header": header(msg.header),
                    "height": msg.height,
                    "width": msg.width,
                    "fields": [{"name": f.name, "offset": f.offset, "datatype": f.datatype,
                                "count": f.count} for f in msg.fields],
                    "is_bigendian": bool(msg.is_bigendian),
                    "point_step": msg.point_step,
                    "row_step": msg.row_step,
                    "data_b64": base64.b64encode(msg.data).decode("ascii"),
                    "is_dense": bool(msg.is_dense),
                }
                kind = "sensor_msgs/msg/PointCloud2"
            elif msg._type in ("livox_ros_driver/CustomMsg", "livox_ros_driver2/CustomMsg"):
                ros2 = {
                    "header": header(msg.header),
                    "timebase": str(msg.timebase),
                    "point_num": msg.point_num,
                    "lidar_id": msg.lidar_id,
                    "rsvd": list(bytearray(msg.rsvd)),
                    "points_b64": base64.b64encode(b"".join(
                        struct.pack("<IfffBBB", p.offset_time, p.x, p.y, p.z, p.reflectivity,
                                    p.tag, p.line) for p in msg.points)).decode("ascii"),
                }
                kind = livox_type
            elif msg._type == "tf2_msgs/TFMessage":
                ros2 = {"transforms": [{
                    "header": header(t.header),
                    "child_frame_id": t.child_frame_id,
                    "transform": {"translation": vector(t.transform.translation),
                                  "rotation": {"x": t.transform.rotation.x,
                                               "y": t.transform.rotation.y,
                                               "z": t.transform.rotation.z,
                                               "w": t.transform.rotation.w}},
                } for t in msg.transforms]}
                kind = "tf2_msgs/msg/TFMessage"
            else:
                continue
            # repr() of a float round-trips; json.dumps uses it.
            out.write(json.dumps({"topic": topic, "type": kind, "record_ns": record_ns,
                                  "msg": ros2}) + "\n")


if __name__ == "__main__":
    main()
