#!/usr/bin/python3
"""Writes a ROS 1 bag from a list of serialized messages, with Debian's python3-rosbag (tests only).

usage: write_ros1_bag.py OUT.bag none|bz2|lz4 MESSAGES
MESSAGES holds records of topic, type (uint32 length + bytes each), an int64 time in ns and the serialized
message (uint32 length + bytes), as src/vmap/testing/recording_writer.cc writes them.
"""
import struct
import sys

import genpy
import rosbag

# The md5 sums ROS 1 gives these types; the reader does not check them, rosbag wants them.
MD5 = {
    "sensor_msgs/Image": "060021388200f6f0f447d0fcd9c64743",
    "sensor_msgs/CompressedImage": "8f7a12909da2c9d3332d540a0977563f",
    "sensor_msgs/CameraInfo": "c9a58c1b0b154e0e6da7578cb991d214",
    "nav_msgs/Odometry": "cd5e73d190d741a2f92e81eda573aca7",
}


def read_string(data, at):
    (length,) = struct.unpack_from("<I", data, at)
    return data[at + 4:at + 4 + length], at + 4 + length


def main():
    out, compression, messages = sys.argv[1:4]
    with open(messages, "rb") as f:
        data = f.read()
    with rosbag.Bag(out, "w", compression=compression, chunk_threshold=64 * 1024) as bag:
        at = 0
        while at < len(data):
            topic, at = read_string(data, at)
            kind, at = read_string(data, at)
            (time_ns,) = struct.unpack_from("<q", data, at)
            payload, at = read_string(data, at + 8)
            kind = kind.decode()
            pytype = type(kind.replace("/", "_"), (), {"_md5sum": MD5.get(kind, "*"), "_full_text": ""})
            bag.write(topic.decode(), (kind, payload, MD5.get(kind, "*"), pytype),
                      genpy.Time(time_ns // 10**9, time_ns % 10**9), raw=True)


if __name__ == "__main__":
    main()
