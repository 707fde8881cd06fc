#!/usr/bin/python3
"""Writes the fuzzers' seed corpus (fuzz/corpus/<harness>/): small valid
inputs of each parser, from which libFuzzer mutates. Run with Debian's
/usr/bin/python3 (python3-rosbag), the lz4 command and node (the ROS 2
bags come from the reference libraries, tests/oracle/write_ros2_bags.mjs);
the output is committed, so this runs only when a seed is added.
    fuzz/make_seed_corpus.py"""
import base64
import io
import json
import os
import shutil
import sqlite3
import struct
import subprocess
import tempfile

import rosbag
import rospy
from sensor_msgs.msg import Imu, PointCloud2, PointField

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CORPUS = os.path.join(HERE, 'corpus')
ROS2_WRITER = os.path.join(ROOT, 'tests', 'oracle', 'write_ros2_bags.mjs')
HARNESSES = ('ros1_bag_reader', 'record_stream', 'text_proto', 'point_cloud2', 'cdr_messages',
             'mcap_reader', 'sqlite_bag_reader', 'rosbag2_metadata')


def xxh32(data, seed=0):
    """XXH32 (xxHash specification), the checksum of LZ4 frames."""
    p1, p2, p3, p4, p5 = 2654435761, 2246822519, 3266489917, 668265263, 374761393
    mask = 0xffffffff
    rotl = lambda x, r: ((x << r) | (x >> (32 - r))) & mask
    n, i = len(data), 0
    if n >= 16:
        v = [(seed + p1 + p2) & mask, (seed + p2) & mask, seed, (seed - p1) & mask]
        while i + 16 <= n:
            for k in range(4):
                lane = struct.unpack_from('<I', data, i + 4 * k)[0]
                v[k] = (rotl((v[k] + lane * p2) & mask, 13) * p1) & mask
            i += 16
        acc = (rotl(v[0], 1) + rotl(v[1], 7) + rotl(v[2], 12) + rotl(v[3], 18)) & mask
    else:
        acc = (seed + p5) & mask
    acc = (acc + n) & mask
    while i + 4 <= n:
        acc = (rotl((acc + struct.unpack_from('<I', data, i)[0] * p3) & mask, 17) * p4) & mask
        i += 4
    while i < n:
        acc = (rotl((acc + data[i] * p5) & mask, 11) * p1) & mask
        i += 1
    acc ^= acc >> 15
    acc = (acc * p2) & mask
    acc ^= acc >> 13
    acc = (acc * p3) & mask
    return acc ^ (acc >> 16)


def stored_lz4_frame(data, checksum, block=256 * 1024):
    """One LZ4 frame of stored (uncompressed) independent blocks, as the
    decode stage writes scans with scans_output.store_blocks true."""
    flg = 0x60 | (0x04 if checksum else 0)
    descriptor = bytes([flg, 0x50])
    out = b'\x04\x22\x4d\x18' + descriptor + bytes([(xxh32(descriptor) >> 8) & 0xff])
    for start in range(0, len(data), block):
        piece = data[start:start + block]
        out += struct.pack('<I', len(piece) | 0x80000000) + piece
    out += struct.pack('<I', 0)
    if checksum:
        out += struct.pack('<I', xxh32(data))
    return out


def varint(n):
    out = b''
    while True:
        byte = n & 0x7f
        n >>= 7
        if n:
            out += bytes([byte | 0x80])
        else:
            return out + bytes([byte])


def field(number, wire_type, payload):
    key = varint((number << 3) | wire_type)
    if wire_type == 0:
        return key + varint(payload)
    if wire_type == 1:
        return key + struct.pack('<d', payload)
    return key + varint(len(payload)) + payload


def vector3(x, y, z):
    return field(1, 1, x) + field(2, 1, y) + field(3, 1, z)


def delimited(message):
    return varint(len(message)) + message


def stream(payload_type, records):
    header = field(1, 2, payload_type.encode()) + field(2, 0, 2) + \
        field(3, 2, field(1, 2, b'make_seed_corpus'))
    end_mark = varint(0) + delimited(field(1, 0, len(records)))
    return b'TILTCAL1' + delimited(header) + b''.join(delimited(r) for r in records) + end_mark


def imu_records():
    return [field(1, 0, 1700000000000000000 + i * 5000000) +
            field(2, 2, vector3(0.01 * i, 0.0, -0.02)) +
            field(3, 2, vector3(0.1, -0.2, 9.81)) for i in range(6)]


def scan_records():
    records = []
    for k in range(2):
        floats = lambda values: struct.pack('<%df' % len(values), *values)
        n = 5
        records.append(field(1, 0, k) + field(2, 0, 1700000000000000000 + k * 100000000) +
                       field(4, 2, b'lidar') +
                       field(5, 2, floats([1.0 + i for i in range(n)])) +
                       field(6, 2, floats([0.5] * n)) + field(7, 2, floats([-1.0] * n)) +
                       field(8, 2, floats([7.0] * n)) +
                       field(9, 2, b''.join(varint(i) for i in range(n))) +
                       field(10, 2, b''.join(varint(2 * i) for i in range(n))) +  # zigzag
                       field(11, 0, 1))
    return records


def cloud(layout, stamp, n=8):
    """A PointCloud2 in a driver's layout: velodyne, ouster or hesai."""
    f32, f64, u16, u32 = PointField.FLOAT32, PointField.FLOAT64, PointField.UINT16, PointField.UINT32
    if layout == 'velodyne':
        fields = [('x', 0, f32), ('y', 4, f32), ('z', 8, f32), ('intensity', 12, f32),
                  ('ring', 16, u16), ('time', 18, f32)]
        fmt, step = '<ffffHf', 22
        point = lambda i: (1.0 + i, 2.0, -0.5, 3.0, i % 16, 0.001 * i)
    elif layout == 'ouster':
        fields = [('x', 0, f32), ('y', 4, f32), ('z', 8, f32), ('intensity', 16, f32),
                  ('t', 20, u32), ('ring', 24, u16)]
        fmt, step = '<fff4xfIH6x', 32
        point = lambda i: (1.0 + i, 2.0, -0.5, 3.0, 1000 * i, i % 16)
    else:
        fields = [('x', 0, f32), ('y', 4, f32), ('z', 8, f32), ('intensity', 12, f32),
                  ('timestamp', 16, f64), ('ring', 24, u16)]
        fmt, step = '<ffffdH', 26
        point = lambda i: (1.0 + i, 2.0, -0.5, 3.0, stamp.to_sec() + 1e-4 * i, i % 16)
    msg = PointCloud2()
    msg.header.stamp = stamp
    msg.header.frame_id = 'lidar'
    msg.height, msg.width = 1, n
    msg.fields = [PointField(name, offset, datatype, 1) for name, offset, datatype in fields]
    msg.is_bigendian = False
    msg.point_step = step
    msg.row_step = step * n
    msg.data = b''.join(struct.pack(fmt, *point(i)) for i in range(n))
    msg.is_dense = True
    return msg


def imu(stamp, i):
    msg = Imu()
    msg.header.stamp = stamp
    msg.header.seq = i
    msg.angular_velocity.z = 0.01 * i
    msg.linear_acceleration.z = 9.81
    return msg


def write_bag(path, compression, layout):
    with rosbag.Bag(path, 'w', compression=compression, chunk_threshold=2048) as bag:
        for i in range(20):
            t = rospy.Time(1700000000, i * 5000000)
            bag.write('/imu/data', imu(t, i), t)
            if i % 10 == 0:
                bag.write('/points', cloud(layout, t), t)


def serialized(msg):
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return buffer.getvalue()


def ros2_messages():
    """Four IMU messages and one small cloud (3 points, Velodyne layout) as
    the JSON lines write_ros2_bags.mjs reads."""
    lines = []
    for i in range(4):
        stamp = {'sec': 1700000000, 'nanosec': i * 5000000}
        lines.append({'topic': '/imu', 'type': 'sensor_msgs/msg/Imu',
                      'record_ns': str(1700000000 * 10**9 + i * 5000000),
                      'msg': {'header': {'stamp': stamp, 'frame_id': 'imu_link'},
                              'orientation': {'x': 0.0, 'y': 0.0, 'z': 0.0, 'w': 1.0},
                              'orientation_covariance': [0.0] * 9,
                              'angular_velocity': {'x': 0.01 * i, 'y': 0.0, 'z': -0.02},
                              'angular_velocity_covariance': [0.0] * 9,
                              'linear_acceleration': {'x': 0.1, 'y': -0.2, 'z': 9.81},
                              'linear_acceleration_covariance': [0.0] * 9}})
    fields = [('x', 0, 7), ('y', 4, 7), ('z', 8, 7), ('intensity', 12, 7), ('ring', 16, 4),
              ('time', 18, 7)]
    data = b''.join(struct.pack('<ffffHf', 1.0 + i, 2.0, -0.5, 3.0, i, 0.001 * i)
                    for i in range(3))
    lines.insert(2, {'topic': '/points', 'type': 'sensor_msgs/msg/PointCloud2',
                     'record_ns': str(1700000000 * 10**9 + 7000000),
                     'msg': {'header': {'stamp': {'sec': 1700000000, 'nanosec': 7000000},
                                        'frame_id': 'lidar'},
                             'height': 1, 'width': 3,
                             'fields': [{'name': n, 'offset': o, 'datatype': d, 'count': 1}
                                        for n, o, d in fields],
                             'is_bigendian': False, 'point_step': 22, 'row_step': 66,
                             'data_b64': base64.b64encode(data).decode(), 'is_dense': True}})
    return ''.join(json.dumps(line) + '\n' for line in lines)


def write_ros2_seeds():
    """MCAP files (stored, lz4, zstd; with and without summary), a rosbag2
    sqlite3 bag, its metadata.yaml and CDR messages (little and big endian),
    written by the reference libraries (scripts/sanitize_and_fuzz.sh adds the
    ROS 2 fixtures of ../shared/fixtures as seeds when present)."""
    with tempfile.TemporaryDirectory() as tmp:
        jsonl = os.path.join(tmp, 'messages.jsonl')
        open(jsonl, 'w').write(ros2_messages())
        mcaps = os.path.join(CORPUS, 'mcap_reader')
        for name, options in (('stored', ['--compression=none']),
                              ('lz4', ['--compression=lz4']),
                              ('zstd', ['--compression=zstd']),
                              ('lz4_no_summary', ['--compression=lz4', '--no-summary']),
                              ('big_endian', ['--compression=none', '--big-endian'])):
            subprocess.run(['node', ROS2_WRITER, os.path.join(mcaps, name + '.mcap'),
                            '--format=mcap', '--messages=' + jsonl] + options, check=True)
        for endian, options in (('le', []), ('be', ['--big-endian'])):
            folder = os.path.join(tmp, 'sqlite_' + endian)
            subprocess.run(['node', ROS2_WRITER, folder, '--format=sqlite3',
                            '--messages=' + jsonl] + options, check=True)
            db3 = os.path.join(folder, 'sqlite_%s_0.db3' % endian)
            if endian == 'le':
                shutil.copy(db3, os.path.join(CORPUS, 'sqlite_bag_reader', 'oracle.db3'))
                shutil.copy(os.path.join(folder, 'metadata.yaml'),
                            os.path.join(CORPUS, 'rosbag2_metadata', 'oracle.yaml'))
            with sqlite3.connect(db3) as db:
                rows = db.execute('SELECT m.id, t.type, m.data FROM messages m JOIN topics t '
                                  'ON m.topic_id = t.id ORDER BY m.id').fetchall()
            kept = set()
            for row_id, msg_type, data in rows:
                kind = msg_type.rsplit('/', 1)[-1]
                if kind in kept:
                    continue
                kept.add(kind)
                open(os.path.join(CORPUS, 'cdr_messages', '%s_%s.cdr' % (kind.lower(), endian)),
                     'wb').write(data)
    open(os.path.join(CORPUS, 'rosbag2_metadata', 'flow_list.yaml'), 'w').write(
        'rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n'
        '  relative_file_paths: [a_0.db3, "a_1.db3", \'a_2.db3\']\n'
        '  compression_format: ""\n  compression_mode: ""\n')


def write_stored_frames(streams):
    """The scans seed in LZ4 frames of stored blocks, with and without the
    content checksum (decode params scans_output)."""
    plain = open(os.path.join(streams, 'scans.binpb'), 'rb').read()
    open(os.path.join(streams, 'scans.stored.binpb.lz4'), 'wb').write(
        stored_lz4_frame(plain, True))
    open(os.path.join(streams, 'scans.stored_no_checksum.binpb.lz4'), 'wb').write(
        stored_lz4_frame(plain, False))


def main():
    shutil.rmtree(CORPUS, ignore_errors=True)
    for harness in HARNESSES:
        os.makedirs(os.path.join(CORPUS, harness))
    bags = os.path.join(CORPUS, 'ros1_bag_reader')
    for compression, layout in (('none', 'velodyne'), ('bz2', 'ouster'), ('lz4', 'hesai')):
        write_bag(os.path.join(bags, '%s_%s.bag' % (compression, layout)), compression, layout)
    data = open(os.path.join(bags, 'none_velodyne.bag'), 'rb').read()
    open(os.path.join(bags, 'unindexed.bag'), 'wb').write(data[:len(data) * 3 // 4])

    streams = os.path.join(CORPUS, 'record_stream')
    for name, payload, records in (('imu.binpb', 'tiltcal.proto.ImuSample', imu_records()),
                                   ('scans.binpb', 'tiltcal.proto.Scan', scan_records())):
        path = os.path.join(streams, name)
        open(path, 'wb').write(stream(payload, records))
        subprocess.run(['lz4', '-q', '-f', '-B4', path, path + '.lz4'], check=True)
    write_stored_frames(streams)

    texts = os.path.join(CORPUS, 'text_proto')
    for stage in ('calibrate', 'decode'):
        shutil.copy(os.path.join(ROOT, 'stages', stage, 'default_params.txtpb'),
                    os.path.join(texts, stage + '.txtpb'))
    open(os.path.join(texts, 'rig.txtpb'), 'w').write(
        'imu_from_lidar { rotation { w: 0.7071067811865476 z: 0.7071067811865476 }\n'
        '  translation { x: 0.1 y: -0.02 z: 0.3 } }\nimu_height_m: 0.35\n'
        'gravity_flat_in_imu { z: -9.81 }\nimu_accel_unit: MPS2\nimu_topic: "/imu/data"\n')

    clouds = os.path.join(CORPUS, 'point_cloud2')
    for layout in ('velodyne', 'ouster', 'hesai'):
        open(os.path.join(clouds, layout + '.msg'), 'wb').write(
            serialized(cloud(layout, rospy.Time(1700000000, 0))))

    write_ros2_seeds()


if __name__ == '__main__':
    main()
