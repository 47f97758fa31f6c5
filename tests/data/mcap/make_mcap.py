#!/usr/bin/python3
"""TEST-ONLY MCAP writer (https://mcap.dev/spec), written apart from the reader in io/formats/src/mcap_*: it
repackages the CDR messages of the shared rosbag2 bags (../shared/data/rosbag, read with sqlite3)
into .mcap files for tests/test_io_mcap.cpp, the fuzz seeds and bench/bench_ros_payloads.cpp.

  /usr/bin/python3 tests/data/mcap/make_mcap.py OUT_DIR [SHARED_DATA_DIR]

Writes into OUT_DIR:
  {evt3,libcaer,mono}_{none,zstd,lz4}.mcap  every message of the bag, chunks uncompressed / zstd /
      lz4 (LZ4 frame format), with Schema and Channel records inside the chunks, MessageIndex
      records after each chunk, DataEnd, a summary (Schema, Channel, Statistics, ChunkIndex) and
      the Footer; small chunks so that each file has several. The mono files also carry a
      std_msgs/msg/String topic (/chatter) that is not events, interleaved with the events.
  mono_unchunked.mcap  messages as top-level records, no summary (Footer summary_start = 0), and
      no data-section or summary CRC (0: not given); every other file states both.
  evt3_reversed.mcap   zstd; inside each chunk the messages are written in reverse log-time order.
  libcaer_swapped.mcap zstd; messages 20-39 written before messages 0-19 (chunks out of time order).
  {evt3,mono}_{zstd,lz4}_frames.mcap  each chunk compressed as three concatenated frames (the
      second without its content size; lz4: no stored size), with a skippable frame between
      the second and the third.
  {evt3,mono}_zstd_datacrc.mcap  one byte of the Header's library string changed after the CRCs
      were computed: only the DataEnd's data-section CRC can tell.
  {evt3,mono}_zstd_summarycrc.mcap  one byte of the last ChunkIndex record (in the summary)
      changed: only the Footer's summary CRC can tell.
  mono_ros1.mcap       zstd; the mono events as ROS 1 dvs_msgs/EventArray messages (message
      encoding ros1, schema encoding ros1msg: what `mcap convert` makes of a ROS 1 bag).
Deterministic. Needs Debian's python3-zstandard and python3-lz4.
"""
import os
import sqlite3
import struct
import sys
import zlib

import lz4.frame
import zstandard

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..'))
from ros_mono_dvs import mono_packet_as_dvs  # noqa: E402
MAGIC = b'\x89MCAP0\r\n'
BAGS = {  # name: (shared bag file, chunk size in bytes)
    'evt3': ('rosbag/test_data_evt3_trigger/test_data_evt3_trigger_0.db3', 64 << 10),
    'libcaer': ('rosbag/test_data_libcaer_rollover/libcaer_rollover_0.db3', 256 << 10),
    'mono': ('rosbag/test_data_mono_cd/test_data_mono_cd_0.db3', 1 << 10),
}
# Op codes
HEADER, FOOTER, SCHEMA, CHANNEL, MESSAGE, CHUNK, MESSAGE_INDEX, CHUNK_INDEX = 1, 2, 3, 4, 5, 6, 7, 8
STATISTICS, DATA_END = 0x0B, 0x0F


def record(op, content):
    return struct.pack('<BQ', op, len(content)) + content


def string(s):
    b = s.encode()
    return struct.pack('<I', len(b)) + b


def prefixed(b):
    return struct.pack('<I', len(b)) + b


def bag_messages(path):
    """[(topic, type, cdr data, log time ns)] in (timestamp, id) order."""
    db = sqlite3.connect('file:' + path + '?mode=ro', uri=True)
    rows = db.execute('SELECT t.name, t.type, m.data, m.timestamp FROM messages m JOIN topics t '
                      'ON m.topic_id = t.id ORDER BY m.timestamp, m.id').fetchall()
    db.close()
    return [(n, ty, bytes(d), ts) for n, ty, d, ts in rows]


def with_chatter(messages):
    """Interleaves a std_msgs/msg/String message before each event message."""
    out = []
    for i, (n, ty, d, ts) in enumerate(messages):
        text = b'hello %d\0' % i
        out.append(('/chatter', 'std_msgs/msg/String', b'\0\1\0\0' + struct.pack('<I', len(text)) + text, ts))
        out.append((n, ty, d, ts))
    return out


def compress(data, how, frames=False):
    if frames:  # three frames, a skippable frame before the third
        a, b = len(data) // 3, 2 * len(data) // 3
        parts = [data[:a], data[a:b], data[b:]]
        skippable = struct.pack('<II', 0x184D2A50, 5) + b'skip!'  # the same magic range in zstd and lz4
        if how == 'zstd':
            return (zstandard.ZstdCompressor(level=3).compress(parts[0]) +
                    zstandard.ZstdCompressor(level=3, write_content_size=False).compress(parts[1]) +
                    skippable + zstandard.ZstdCompressor(level=3).compress(parts[2]))
        return (lz4.frame.compress(parts[0]) + lz4.frame.compress(parts[1], store_size=False) +
                skippable + lz4.frame.compress(parts[2]))
    if how == 'zstd':
        return zstandard.ZstdCompressor(level=3).compress(data)
    if how == 'lz4':
        return lz4.frame.compress(data)
    return data


class Writer:
    def __init__(self, compression, chunk_size, chunked=True, summary=True, reverse=False, crc=True,
                 frames=False, ros1=False):
        self.compression, self.chunk_size = compression, chunk_size
        self.encoding, self.schema_encoding = ('ros1', 'ros1msg') if ros1 else ('cdr', 'ros2msg')
        self.chunked, self.summary, self.reverse = chunked, summary, reverse
        self.crc, self.frames = crc, frames
        self.out = bytearray(MAGIC + record(HEADER, string('ros1' if ros1 else 'ros2') +
                                            string('evlife make_mcap.py')))
        self.schemas, self.channels = {}, {}  # type -> schema id, topic -> (channel id, schema id)
        self.counts, self.chunk_indexes = {}, []
        self.pending = []  # records of the open chunk: (log time, bytes, channel or None)
        self.times = []

    def _ids(self, topic, type_):
        new = []
        if type_ not in self.schemas:
            self.schemas[type_] = len(self.schemas) + 1
            new.append(record(SCHEMA, struct.pack('<H', self.schemas[type_]) + string(type_) +
                              string(self.schema_encoding) + prefixed(b'')))
        if topic not in self.channels:
            self.channels[topic] = (len(self.channels) + 1, self.schemas[type_])
            new.append(self._channel_record(topic))
        return self.channels[topic][0], new

    def _channel_record(self, topic):
        cid, sid = self.channels[topic]
        return record(CHANNEL, struct.pack('<HH', cid, sid) + string(topic) + string(self.encoding) +
                      prefixed(string('offered_qos_profiles') + string('')))

    def add(self, topic, type_, data, log_time):
        cid, new = self._ids(topic, type_)
        seq = self.counts.get(cid, 0)
        self.counts[cid] = seq + 1
        self.times.append(log_time)
        msg = record(MESSAGE, struct.pack('<HIQQ', cid, seq, log_time, log_time) + data)
        if not self.chunked:
            self.out += b''.join(new) + msg
            return
        self.pending += [(None, r, None) for r in new] + [(log_time, msg, cid)]
        if sum(len(r) for _, r, _ in self.pending) >= self.chunk_size:
            self.flush()

    def flush(self):
        if not self.pending:
            return
        heads = [p for p in self.pending if p[0] is None]
        msgs = [p for p in self.pending if p[0] is not None]
        if self.reverse:
            msgs.reverse()
        records, index = bytearray(), {}
        for t, r, cid in heads + msgs:
            if cid is not None:
                index.setdefault(cid, []).append((t, len(records)))
            records += r
        times = [t for t, _, _ in msgs]
        body = compress(bytes(records), self.compression, self.frames)
        chunk_at = len(self.out)
        self.out += record(CHUNK, struct.pack('<QQQI', min(times), max(times), len(records),
                                              zlib.crc32(records)) + string(self.compression) +
                           struct.pack('<Q', len(body)) + body)
        chunk_len = len(self.out) - chunk_at
        index_at, offsets = len(self.out), b''
        for cid in sorted(index):
            offsets += struct.pack('<HQ', cid, len(self.out))
            self.out += record(MESSAGE_INDEX, struct.pack('<H', cid) +
                               prefixed(b''.join(struct.pack('<QQ', t, o) for t, o in index[cid])))
        self.chunk_indexes.append(record(CHUNK_INDEX, struct.pack('<QQQQ', min(times), max(times), chunk_at, chunk_len) +
                                         prefixed(offsets) + struct.pack('<Q', len(self.out) - index_at) +
                                         string(self.compression) + struct.pack('<QQ', len(body), len(records))))
        self.pending = []

    def finish(self):
        self.flush()
        # Data section CRC: every byte from the file's start to the DataEnd record.
        self.data_end_at = len(self.out)
        self.out += record(DATA_END, struct.pack('<I', zlib.crc32(self.out) if self.crc else 0))
        summary_start = 0
        if self.summary:
            summary_start = len(self.out)
            for type_, sid in self.schemas.items():
                self.out += record(SCHEMA, struct.pack('<H', sid) + string(type_) + string('ros2msg') + prefixed(b''))
            for topic in self.channels:
                self.out += self._channel_record(topic)
            counts = b''.join(struct.pack('<HQ', c, n) for c, n in sorted(self.counts.items()))
            self.out += record(STATISTICS, struct.pack('<QHIIIIQQ', sum(self.counts.values()), len(self.schemas),
                                                       len(self.channels), 0, 0, len(self.chunk_indexes),
                                                       min(self.times), max(self.times)) + prefixed(counts))
            for ci in self.chunk_indexes:
                self.out += ci
        # Summary CRC: from the summary's start (the Footer's without one) through the Footer's
        # summary_offset_start field.
        self.footer_at = len(self.out)
        footer = struct.pack('<BQQQ', FOOTER, 20, summary_start, 0)
        covered = self.out[summary_start if summary_start else self.footer_at:] + footer
        self.out += footer + struct.pack('<I', zlib.crc32(covered) if self.crc else 0) + MAGIC
        return bytes(self.out)


def write(path, messages, flip=None, **options):
    """flip(writer) -> offset of one byte to invert after the CRCs were computed."""
    w = Writer(**options)
    for m in messages:
        w.add(*m)
    data = bytearray(w.finish())
    if flip:
        data[flip(w)] ^= 0xFF
    with open(path, 'wb') as f:
        f.write(data)


def header_byte(w):
    return len(MAGIC) + 9 + 4 + 4 + 4 + 3  # inside the library string 'evlife make_mcap.py'


def last_chunk_index_byte(w):
    return w.footer_at - 1  # the high byte of the last ChunkIndex's uncompressed_size


def main():
    out_dir = sys.argv[1]
    data = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, '..', '..', '..', '..', 'shared', 'data')
    os.makedirs(out_dir, exist_ok=True)
    for name, (rel, chunk_size) in BAGS.items():
        messages = bag_messages(os.path.join(data, rel))
        if name == 'mono':
            messages = with_chatter(messages)
        for how in ('none', 'zstd', 'lz4'):
            write(os.path.join(out_dir, '%s_%s.mcap' % (name, how)), messages,
                  compression='' if how == 'none' else how, chunk_size=chunk_size)
        if name in ('evt3', 'mono'):
            for how in ('zstd', 'lz4'):
                write(os.path.join(out_dir, '%s_%s_frames.mcap' % (name, how)), messages, compression=how,
                      chunk_size=chunk_size, frames=True)
            write(os.path.join(out_dir, '%s_zstd_datacrc.mcap' % name), messages, flip=header_byte,
                  compression='zstd', chunk_size=chunk_size)
            write(os.path.join(out_dir, '%s_zstd_summarycrc.mcap' % name), messages, flip=last_chunk_index_byte,
                  compression='zstd', chunk_size=chunk_size)
        if name == 'mono':
            write(os.path.join(out_dir, 'mono_unchunked.mcap'), messages, compression='', chunk_size=0,
                  chunked=False, summary=False, crc=False)
            events = [(n, 'dvs_msgs/EventArray', mono_packet_as_dvs(d, i), ts)
                      for i, (n, ty, d, ts) in enumerate(bag_messages(os.path.join(data, rel)))]
            write(os.path.join(out_dir, 'mono_ros1.mcap'), events, compression='zstd', chunk_size=chunk_size,
                  ros1=True)
        if name == 'libcaer':
            write(os.path.join(out_dir, 'libcaer_swapped.mcap'), messages[20:40] + messages[:20] + messages[40:],
                  compression='zstd', chunk_size=chunk_size)
        if name == 'evt3':
            write(os.path.join(out_dir, 'evt3_reversed.mcap'), messages, compression='zstd',
                  chunk_size=chunk_size, reverse=True)


if __name__ == '__main__':
    main()
