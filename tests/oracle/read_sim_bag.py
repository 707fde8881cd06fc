#!/usr/bin/python3
"""Reads a bag written by tiltcal_simulate with the real ROS library (Debian
python3-rosbag, sensor_msgs.point_cloud2) and dumps what it finds, as the
oracle of tests/stages/simulate.

Usage: /usr/bin/python3 read_sim_bag.py BAG OUT [CLOUD_INDICES]
  CLOUD_INDICES: comma-separated indices (0-based, per topic order) of the
  PointCloud2 messages whose points are dumped in full.

Output (OUT), floats as repr() (exact round trip), one item per line:
  compression NAME                    per chunk compression of the bag
  msg TOPIC TYPE RECORD_NS STAMP_NS SEQ FRAME_ID CRC32 SIZE
                                      every message in bag order; CRC32 and
                                      SIZE of the raw serialized bytes
  imu WX WY WZ AX AY AZ GYRO_VAR ACCEL_VAR ORIENT_COV0
                                      after each sensor_msgs/Imu msg line
  cloud INDEX HEIGHT WIDTH POINT_STEP ROW_STEP IS_DENSE IS_BIGENDIAN
                                      after each PointCloud2 msg line
  field NAME OFFSET DATATYPE COUNT    after each cloud line
  p V1 V2 ...                         every point of a dumped cloud
                                      (read_points, skip_nans=False), values
                                      in the order of increasing field offset
"""

import sys
import zlib

import rosbag
import sensor_msgs.point_cloud2 as pc2


def ns(t):
    return t.secs * 1000000000 + t.nsecs


def main():
    bag_path, out_path = sys.argv[1], sys.argv[2]
    wanted = set()
    if len(sys.argv) > 3 and sys.argv[3]:
        wanted = {int(x) for x in sys.argv[3].split(',')}
    lines = []
    with rosbag.Bag(bag_path) as bag:
        info = bag.get_compression_info()
        lines.append('compression %s' % info.compression)
        cloud_index = 0
        for topic, raw, t in bag.read_messages(raw=True):
            datatype, data, md5sum, _, pytype = raw
            msg = pytype()
            msg.deserialize(data)
            h = msg.header
            lines.append('msg %s %s %d %d %d %s %d %d' % (
                topic, datatype, ns(t), ns(h.stamp), h.seq, h.frame_id,
                zlib.crc32(data) & 0xffffffff, len(data)))
            if datatype == 'sensor_msgs/Imu':
                w, a = msg.angular_velocity, msg.linear_acceleration
                lines.append('imu %r %r %r %r %r %r %r %r %r' % (
                    w.x, w.y, w.z, a.x, a.y, a.z,
                    msg.angular_velocity_covariance[0],
                    msg.linear_acceleration_covariance[0],
                    msg.orientation_covariance[0]))
            elif datatype == 'sensor_msgs/PointCloud2':
                lines.append('cloud %d %d %d %d %d %d %d' % (
                    cloud_index, msg.height, msg.width, msg.point_step,
                    msg.row_step, int(msg.is_dense), int(msg.is_bigendian)))
                for f in msg.fields:
                    lines.append('field %s %d %d %d' % (f.name, f.offset, f.datatype, f.count))
                if cloud_index in wanted:
                    for p in pc2.read_points(msg, skip_nans=False):
                        lines.append('p ' + ' '.join(repr(v) for v in p))
                cloud_index += 1
    with open(out_path, 'w') as out:
        out.write('\n'.join(lines) + '\n')


if __name__ == '__main__':
    main()
