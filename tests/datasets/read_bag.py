#!/usr/bin/python3
"""Reads a ROS 1 bag with Debian's python3-rosbag and prints, as JSON, what the bag-export tests
check: per topic its message type, count, record times, header stamps and its first and last
messages (every one for /tf and /tf_static) as nested dictionaries (byte arrays as their length and first bytes; infinities as
strings, which JSON lacks).

Usage: /usr/bin/python3 read_bag.py BAG
"""
import json
import math
import sys

import genpy
import rosbag


def plain(value):
    if isinstance(value, genpy.Message):
        return {slot: plain(getattr(value, slot)) for slot in value.__slots__}
    if isinstance(value, (genpy.Time, genpy.Duration)):
        return value.to_nsec()
    if isinstance(value, (bytes, bytearray)):
        return {"len": len(value), "head": list(value[:16])}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def header_stamp(msg):
    if hasattr(msg, "header"):
        return msg.header.stamp.to_nsec()
    if hasattr(msg, "transforms") and msg.transforms:  # tf2_msgs/TFMessage
        return msg.transforms[0].header.stamp.to_nsec()
    return None


def main():
    topics = {}
    with rosbag.Bag(sys.argv[1]) as bag:
        info = bag.get_type_and_topic_info().topics
        for topic, msg, t in bag.read_messages():
            entry = topics.setdefault(topic, {"type": info[topic].msg_type, "count": 0,
                                              "record_ns": [], "stamps": [], "first": plain(msg)})
            entry["count"] += 1
            entry["record_ns"].append(t.to_nsec())
            entry["stamps"].append(header_stamp(msg))
            entry["last"] = plain(msg)
            if entry["type"] == "tf2_msgs/TFMessage":
                entry.setdefault("messages", []).append(plain(msg))
        for topic, conns in ((c.topic, c) for c in bag._connections.values()):
            if topic in topics:
                latching = conns.header.get("latching", b"0")
                topics[topic]["latching"] = latching.decode() if isinstance(latching, bytes) else latching
    json.dump({"topics": topics}, sys.stdout)


if __name__ == "__main__":
    main()
