#!/usr/bin/python3
"""What other tools say a bag holds, as an oracle for `tiltcal_inspect info
--bag` (tests/stages/inspect/bag_info_test.cc). Debian's /usr/bin/python3.

Usage:
  bag_info_oracle.py rosbag BAG...
      the real ROS 1 library (python3-rosbag), as `rosbag info` reads it:
      {BAG: {"message_count", "start_ns", "end_ns", "topics": {NAME: {"type",
      "message_count", "frequency", "in_time_order", "start_ns", "end_ns"}}}};
      counts, types and frequency from get_type_and_topic_info (frequency: 1
      / the median interval of the index entries' times in the order rosbag
      reads them, null when rosbag gives none; in_time_order: whether that
      order is the time order), times exact in ns from the index entries
      (null without messages).
  bag_info_oracle.py rosbag2-metadata FOLDER
      FOLDER/metadata.yaml read with PyYAML: {"storage_identifier",
      "message_count", "starting_time_ns", "duration_ns", "topics": {NAME:
      {"type", "serialization_format", "message_count"}}}.
Exit 3 when the library is missing (the caller skips).
"""

import json
import sys


def rosbag_figures(path):
    try:
        import rosbag
    except ImportError:
        sys.exit(3)
    with rosbag.Bag(path) as bag:
        info = bag.get_type_and_topic_info()
        topics = {}
        first = last = None
        for name, t in info.topics.items():
            times = [e.time.to_nsec() for e in bag._get_entries(bag._get_connections([name]))]
            topics[name] = {
                "type": t.msg_type,
                "message_count": t.message_count,
                "frequency": t.frequency,
                "in_time_order": times == sorted(times),
                "start_ns": min(times) if times else None,
                "end_ns": max(times) if times else None,
            }
            if times:
                first = min(times) if first is None else min(first, min(times))
                last = max(times) if last is None else max(last, max(times))
        return {"message_count": bag.get_message_count(), "start_ns": first, "end_ns": last,
                "topics": topics}


def rosbag2_figures(folder):
    try:
        import yaml
    except ImportError:
        sys.exit(3)
    with open(folder + "/metadata.yaml") as f:
        m = yaml.safe_load(f)["rosbag2_bagfile_information"]
    topics = {}
    for entry in m.get("topics_with_message_count", []):
        t = entry["topic_metadata"]
        topics[t["name"]] = {"type": t["type"], "serialization_format": t["serialization_format"],
                             "message_count": entry["message_count"]}
    return {"storage_identifier": m["storage_identifier"], "message_count": m["message_count"],
            "starting_time_ns": m["starting_time"]["nanoseconds_since_epoch"],
            "duration_ns": m["duration"]["nanoseconds"], "topics": topics}


def main():
    mode = sys.argv[1]
    if mode == "rosbag":
        figures = {path: rosbag_figures(path) for path in sys.argv[2:]}
    else:
        figures = rosbag2_figures(sys.argv[2])
    json.dump(figures, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
