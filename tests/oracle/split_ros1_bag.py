#!/usr/bin/python3
"""Splits a ROS1 bag into several bags with the real ROS library (Debian
python3-rosbag), the two ways recordings come split:

  --by=time --parts=N [--overlap_s=S]   OUT/NAME_0.bag ... NAME_{N-1}.bag, equal
      record-time spans; each part after the first also holds the last S
      seconds of the part before it (the same messages in two files)
  --by=sensor                           OUT/imu.bag (the sensor_msgs/Imu
      topics) and OUT/lidar.bag (every other topic)

Messages are copied raw (the serialized bytes and record times unchanged);
parts alternate LZ4 and uncompressed chunks (--compression=alternate, the
default), or all have lz4 or none. Prints one line:
"messages M duplicated D" (D: messages written to two parts).

Usage: /usr/bin/python3 split_ros1_bag.py BAG OUT --by=time|sensor [--parts=N] [--overlap_s=S]
           [--compression=alternate|lz4|none]
"""

import argparse
import os

import rosbag


def main():
    p = argparse.ArgumentParser()
    p.add_argument("bag")
    p.add_argument("out")
    p.add_argument("--by", choices=["time", "sensor"], required=True)
    p.add_argument("--parts", type=int, default=2)
    p.add_argument("--overlap_s", type=float, default=0.0)
    p.add_argument("--compression", choices=["alternate", "lz4", "none"], default="alternate")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    name = os.path.splitext(os.path.basename(a.bag))[0]
    compressions = {"alternate": [rosbag.Compression.LZ4, rosbag.Compression.NONE],
                    "lz4": [rosbag.Compression.LZ4], "none": [rosbag.Compression.NONE]}[a.compression]
    with rosbag.Bag(a.bag) as bag:
        start = bag.get_start_time()
        span = bag.get_end_time() - start
        if a.by == "time":
            files = ["%s_%d.bag" % (name, i) for i in range(a.parts)]
        else:
            files = ["imu.bag", "lidar.bag"]
        outs = [rosbag.Bag(os.path.join(a.out, f), "w", compression=compressions[i % len(compressions)])
                for i, f in enumerate(files)]
        messages = duplicated = 0
        for topic, raw, t in bag.read_messages(raw=True):
            messages += 1
            if a.by == "sensor":
                targets = [0 if raw[0] == "sensor_msgs/Imu" else 1]
            else:
                offset = t.to_sec() - start
                part = min(int(offset / span * a.parts), a.parts - 1)
                targets = [part]
                # The next part also starts overlap_s before its span.
                if part + 1 < a.parts and offset >= (part + 1) * span / a.parts - a.overlap_s:
                    targets.append(part + 1)
            duplicated += len(targets) - 1
            for i in targets:
                outs[i].write(topic, raw, t, raw=True)
        for o in outs:
            o.close()
    print("messages %d duplicated %d" % (messages, duplicated))


if __name__ == "__main__":
    main()
