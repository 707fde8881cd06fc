#!/usr/bin/python3
"""Python anchor of the decode benchmark: reads a ROS1 bag with Debian's
python3-rosbag (rosbag.Bag.read_messages, all topics, time order) and touches
every point's x, y, z and time, summing them (same work as
rosbag_cpp_reader.cc), plus the IMU angular velocity and linear acceleration.

--points=read_points  sensor_msgs.point_cloud2.read_points(field_names=
                      ('x','y','z','time')): the library's own per-point path.
--points=numpy        numpy.frombuffer(msg.data) with a structured dtype built
                      from msg.fields (what fast Python users do).
--max_bytes=N         stop after the clouds that together carry >= N bytes of
                      point data (a prefix of the bag; 0 = whole bag). The
                      summary line says how much of the bag was read.

Prints one line: messages, clouds, points, imu, sums, wall s, and
prefix_fraction (points read / points in the bag's clouds, estimated from the
index: clouds read / clouds in the bag).
"""

import argparse
import sys
import time

import numpy as np
import rosbag
from sensor_msgs import point_cloud2
from sensor_msgs.msg import PointField

NUMPY_TYPES = {PointField.INT8: 'i1', PointField.UINT8: 'u1', PointField.INT16: '<i2',
               PointField.UINT16: '<u2', PointField.INT32: '<i4', PointField.UINT32: '<u4',
               PointField.FLOAT32: '<f4', PointField.FLOAT64: '<f8'}


def cloud_dtype(msg):
    return np.dtype({'names': [f.name for f in msg.fields],
                     'formats': [NUMPY_TYPES[f.datatype] for f in msg.fields],
                     'offsets': [f.offset for f in msg.fields],
                     'itemsize': msg.point_step})


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('bag')
    parser.add_argument('--points', choices=['read_points', 'numpy'], default='read_points')
    parser.add_argument('--max_bytes', type=int, default=0)
    args = parser.parse_args()

    start = time.perf_counter()
    num_messages = num_clouds = num_points = num_imu = 0
    cloud_bytes = 0
    sum_xyz = sum_time_s = sum_imu = 0.0
    with rosbag.Bag(args.bag) as bag:
        info = bag.get_type_and_topic_info()
        clouds_in_bag = sum(t.message_count for t in info.topics.values()
                            if t.msg_type == 'sensor_msgs/PointCloud2')
        for _, msg, _ in bag.read_messages():
            num_messages += 1
            kind = msg._type
            if kind == 'sensor_msgs/PointCloud2':
                if args.points == 'read_points':
                    for x, y, z, t in point_cloud2.read_points(
                            msg, field_names=('x', 'y', 'z', 'time'), skip_nans=False):
                        sum_xyz += x + y + z
                        sum_time_s += t
                else:
                    points = np.frombuffer(msg.data, dtype=cloud_dtype(msg),
                                           count=msg.width * msg.height)
                    sum_xyz += float(points['x'].sum(dtype=np.float64) +
                                     points['y'].sum(dtype=np.float64) +
                                     points['z'].sum(dtype=np.float64))
                    sum_time_s += float(points['time'].sum(dtype=np.float64))
                num_points += msg.width * msg.height
                num_clouds += 1
                cloud_bytes += len(msg.data)
                if args.max_bytes and cloud_bytes >= args.max_bytes:
                    break
            elif kind == 'sensor_msgs/Imu':
                a, w = msg.linear_acceleration, msg.angular_velocity
                sum_imu += w.x + w.y + w.z + a.x + a.y + a.z
                num_imu += 1
    wall_s = time.perf_counter() - start
    print('rosbag_python_reader: points_mode=%s messages=%d clouds=%d points=%d imu=%d '
          'sum_xyz=%.6e sum_time_s=%.6e sum_imu=%.6e wall_s=%.3f prefix_fraction=%.4f' %
          (args.points, num_messages, num_clouds, num_points, num_imu, sum_xyz, sum_time_s,
           sum_imu, wall_s, num_clouds / max(clouds_in_bag, 1)))


if __name__ == '__main__':
    sys.exit(main())
