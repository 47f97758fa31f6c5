#!/usr/bin/python3
"""Writes the ROS 1 test bags of tests/test_io_rosbag1.cpp with Debian's python3-rosbag
(an independent bag writer), from the messages of the shared ROS 2 bags (../shared/data/rosbag):

  evt3_{none,bz2,lz4}.bag  the first 30 messages of test_data_evt3_trigger as
                           event_camera_msgs/EventPacket (ROS 1 serialization), chunks
                           uncompressed / bz2 / lz4, small chunks so that the bag has several
  mono_dvs.bag             the 100 events of test_data_mono_cd as dvs_msgs/EventArray (2
                           messages), plus a std_msgs/String topic that is not events
  mono_dv_ros.bag          the same events as dv_ros_msgs/EventArray (iniVation's dv-ros
                           driver: the dvs_msgs layout under its own name)
  evt3_interrupted.bag.active
                           the 30 messages of evt3_none.bag as a recording that stopped
                           without closing its bag (rosbag record killed, power lost): the
                           bytes on disk before close(), i.e. index_pos 0, no index, the
                           chunk being written with its placeholder sizes

  /usr/bin/python3 tests/data/ros1/make_bags.py [SHARED_DATA_DIR]
The EventPacket md5sum written is a placeholder (no reader here checks it). Deterministic;
the checked-in bags are its output. Needs the Debian package python3-rosbag (not needed by CI:
the bags are checked in).
"""
import os
import shutil
import sqlite3
import struct
import sys

import rosbag
import rospy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
from ros_mono_dvs import DVS_MD5, DVS_TEXT, Cdr, mono_packet_as_dvs, ros1_header  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, '..', '..', '..', '..', 'shared', 'data')


def messages(rel, limit):
    db = sqlite3.connect('file:' + os.path.join(DATA, rel) + '?mode=ro', uri=True)
    rows = db.execute('SELECT data, timestamp FROM messages ORDER BY timestamp, id LIMIT ?', (limit,)).fetchall()
    db.close()
    return [(bytes(d), t) for d, t in rows]


_classes = {}


def Raw(type_, md5, text, payload):
    """A message already serialized (rosbag needs only these class attributes and serialize())."""
    if type_ not in _classes:
        _classes[type_] = type(type_.replace('/', '_'), (), {
            '_type': type_, '_md5sum': md5, '_full_text': text, '_has_header': True,
            '__init__': lambda self, payload: setattr(self, 'payload', payload),
            'serialize': lambda self, buff: buff.write(self.payload)})
    return _classes[type_](payload)


PACKET_TEXT = ('std_msgs/Header header\nuint32 height\nuint32 width\nuint64 seq\nuint64 time_base\n'
               'string encoding\nbool is_bigendian\nuint8[] events\n')

packets = []
for i, (m, t) in enumerate(messages('rosbag/test_data_evt3_trigger/test_data_evt3_trigger_0.db3', 30)):
    c = Cdr(m)
    sec, nsec = c.get('i'), c.get('I')
    frame = c.string()
    height, width = c.get('I'), c.get('I')
    seq, time_base = c.get('Q'), c.get('Q')
    encoding = c.string()
    big = c.get('B')
    n = c.get('I')
    payload = m[c.pos:c.pos + n]
    body = (ros1_header(i, sec, nsec, frame) + struct.pack('<IIQQ', height, width, seq, time_base) +
            struct.pack('<I', len(encoding)) + encoding + struct.pack('<B', big) + struct.pack('<I', n) + payload)
    packets.append((Raw('event_camera_msgs/EventPacket', '1f4b0c2e8e5a3c7d9b6a4f2e1d0c3b5a', PACKET_TEXT, body), t))

for compression in ('none', 'bz2', 'lz4'):
    with rosbag.Bag(os.path.join(HERE, 'evt3_%s.bag' % compression), 'w', compression=compression,
                    chunk_threshold=64 * 1024) as bag:
        for msg, t in packets:
            bag.write('/event_camera/events', msg, rospy.Time(nsecs=t), raw=False)

# The same packets as a recording that stopped before close(): uncompressed chunks go to the file
# as they are written, so a flush shows what a killed recorder leaves.
active = os.path.join(HERE, 'evt3_interrupted.bag.active')
bag = rosbag.Bag(active + '.tmp', 'w', compression='none', chunk_threshold=64 * 1024)
for msg, t in packets:
    bag.write('/event_camera/events', msg, rospy.Time(nsecs=t), raw=False)
bag._file.flush()
shutil.copyfile(active + '.tmp', active)
bag.close()
os.remove(active + '.tmp')

# mono bag events -> dvs_msgs/EventArray (ts = time_base + dt as ROS time).
dvs_bodies = []
with rosbag.Bag(os.path.join(HERE, 'mono_dvs.bag'), 'w') as bag:
    for i, (m, t) in enumerate(messages('rosbag/test_data_mono_cd/test_data_mono_cd_0.db3', 2)):
        body = mono_packet_as_dvs(m, i)
        dvs_bodies.append((body, t))
        bag.write('/dvs/events', Raw('dvs_msgs/EventArray', DVS_MD5, DVS_TEXT, body),
                  rospy.Time(nsecs=t))
        note = b'hello'
        bag.write('/notes', Raw('std_msgs/String', '992ce8a1687cec8c8bd883ec73ca41d1', 'string data\n',
                                struct.pack('<I', len(note)) + note), rospy.Time(nsecs=t))

# The same messages as dv_ros_msgs/EventArray.
with rosbag.Bag(os.path.join(HERE, 'mono_dv_ros.bag'), 'w') as bag:
    for body, t in dvs_bodies:
        bag.write('/events', Raw('dv_ros_msgs/EventArray', DVS_MD5,
                                 DVS_TEXT.replace('dvs_msgs', 'dv_ros_msgs'), body), rospy.Time(nsecs=t))
