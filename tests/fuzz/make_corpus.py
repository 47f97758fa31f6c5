#!/usr/bin/env python3
"""Writes the seed corpora of tests/fuzz/corpus/<what>/ (small files, a few KB):
cuts of the real recordings of ../shared/data at record boundaries plus small
synthetic files. Run from anywhere; deterministic. The checked-in files are
its output: rerun it only to change the seeds.

  tests/fuzz/make_corpus.py [SHARED_DATA_DIR]

Two seeds come from evlife itself (no Python HDF5 on the CI image):
  corpus/hdf5/from_aedat2_30ev.h5     evlife convert <first 30 events of
                                      corpus/aedat2/real_head_400ev.aedat> X.h5
  corpus/augmented/real_10ev.bin      evlife process <its first 10 events> -o X.bin
and the HDF5 layouts of other tools (v2e, MVSEC, event_utils) from
tests/fuzz/make_hdf5_seeds.cpp (the HDF5 C API; its comment says how to run it).
"""
import os
import random
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, '..', '..', '..', 'shared', 'data')
CORPUS = os.path.join(HERE, 'corpus')
rng = random.Random(1234)


def put(what, name, data):
    d = os.path.join(CORPUS, what)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), 'wb') as f:
        f.write(data)


def read(rel):
    with open(os.path.join(DATA, rel), 'rb') as f:
        return f.read()


def text_header_end(data, marker):
    """Offset of the first byte after the header lines starting with `marker`."""
    pos = 0
    while data.startswith(marker, pos):
        pos = data.index(b'\n', pos) + 1
    return pos


# ---- AEDAT 2.0: the jAER header kept short, then whole 8-byte records.
d = read('aedat2/alex_walking_again.aedat')
h = text_header_end(d, b'#')
short_header = b'#!AER-DAT2.0\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n'
put('aedat2', 'real_head_400ev.aedat', short_header + d[h:h + 400 * 8])
put('aedat2', 'real_tail_100ev.aedat', short_header + d[len(d) - 100 * 8:])
put('aedat2', 'header_only.aedat', short_header)
# special events (bit 15) and a timestamp wrap of the 32-bit clock
recs = b''.join(struct.pack('>II', (rng.randrange(128) << 8) | (rng.randrange(128) << 1) | rng.randrange(2),
                            (0xFFFFFF00 + 16 * i) & 0xFFFFFFFF) for i in range(40))
recs += struct.pack('>II', 0x8000, 0xFFFFFFF0)
put('aedat2', 'synthetic_wrap_special.aedat', short_header + recs)

# ---- AEDAT 4.0: header + the first event and the first imu packet (no data table).
d = read('aedat4/sample.aedat4')
hs = struct.unpack('<i', d[14:18])[0]
pos = 18 + hs
for _ in range(2):
    _, size = struct.unpack('<ii', d[pos:pos + 8])
    pos += 8 + size
put('aedat4', 'real_first_packets.aedat4', d[:pos])
put('aedat4', 'header_only.aedat4', d[:18 + hs])


def aedat4_io_header(xml):
    # size-prefixed IOHeader (compression NONE, no data table, infoNode = xml), as tests/test_io_formats.cpp
    b = bytearray((44 + 4 + len(xml) + 1 + 3) // 4 * 4)
    struct.pack_into('<II4sHHHHHxxIIqII', b, 0, len(b) - 4, 20, b'IOHE', 10, 20, 4, 8, 16, 12, 0, -1, 4, len(xml))
    b[48:48 + len(xml)] = xml
    return bytes(b)


def aedat4_trigger_packet(triggers):
    # size-prefixed TriggerPacket: Trigger tables (timestamp int64, type int8) sharing one vtable
    n = len(triggers)
    vtable = 32 + 4 * n
    first = (vtable + 8 + 7) // 8 * 8
    b = bytearray(first + 16 * n)
    struct.pack_into('<II4sHHHxxIII', b, 0, len(b) - 4, 16, b'TRIG', 6, 8, 4, 8, 4, n)
    struct.pack_into('<HHHH', b, vtable, 8, 16, 8, 4)
    for i, (t, kind) in enumerate(triggers):
        table = first + 16 * i
        struct.pack_into('<I', b, 32 + 4 * i, table - (32 + 4 * i))
        struct.pack_into('<Ibxxxq', b, table, table - vtable, kind, t)
    return bytes(b)


# A trigger stream (5) beside the events (7): a trigger packet of every type between event packets.
xml = (b'<dv version="2.0"><node name="outInfo" path="/mainloop/Recorder/outInfo/">'
       b'<node name="5" path="/mainloop/Recorder/outInfo/5/"><attr key="typeIdentifier" type="string">TRIG</attr></node>'
       b'<node name="7" path="/mainloop/Recorder/outInfo/7/"><attr key="typeIdentifier" type="string">EVTS</attr>'
       b'<node name="info" path="/mainloop/Recorder/outInfo/7/info/"><attr key="sizeX" type="int">346</attr>'
       b'<attr key="sizeY" type="int">260</attr></node></node></node></dv>')


def aedat4_event_packet(t0):
    # size-prefixed EventPacket, its vector of eight 16-byte events at 36
    events = b''.join(struct.pack('<qhhBxxx', t0 + i, 37 * i % 346, 91 * i % 260, i % 2) for i in range(8))
    b = bytearray(40)
    struct.pack_into('<II4sHHHxxII', b, 0, 40 + len(events) - 4, 16, b'EVTS', 6, 8, 4, 8, 12)
    struct.pack_into('<I', b, 36, 8)
    return bytes(b) + events


trig = aedat4_trigger_packet([(1000 + 2 * k, k) for k in range(10)])
body = b''.join(struct.pack('<ii', stream, len(p)) + p
                for stream, p in ((7, aedat4_event_packet(1000)), (5, trig), (7, aedat4_event_packet(1100))))
put('aedat4', 'synthetic_triggers.aedat4', b'#!AER-DAT4.0\r\n' + aedat4_io_header(xml) + body)

# ---- Prophesee RAW EVT 2.0 / 3.0: '%' header, then 32-bit / 16-bit words.
for what, rel, word in (('evt2', 'evt2/evt2_sample.raw', 4), ('evt3', 'evt3/evt3_sample.raw', 2)):
    d = read(rel)
    h = text_header_end(d, b'%')
    put(what, 'real_head.raw', d[:h + 3000 // word * word])
    put(what, 'real_middle.raw', d[:h] + d[len(d) // 2 // word * word:len(d) // 2 // word * word + 2000])
    put(what, 'header_only.raw', d[:h])

# ---- Prophesee RAW EVT 2.1: no shared recording; synthetic 64-bit words as
# Prophesee's EVT 2.1 page lays them out, in both byte orders (GenX320: one
# little-endian 64-bit word; IMX636: two 32-bit halves, the upper one first).
def evt21_words():
    r = random.Random(21)  # its own generator: the other seeds stay as they were
    words = []
    for th in range(1, 9):
        words.append((0x8 << 60) | (th << 32))
        # In time order (a sensor's): unsorted, the seeds stopped at event 29 with a
        # step back, and the fuzzers seldom reached the later words and the trigger.
        for t_low in sorted(r.randrange(64) for _ in range(6)):
            words.append((r.randrange(2) << 60) | (t_low << 54) | (32 * r.randrange(10) << 43)
                         | (r.randrange(320) << 32) | r.randrange(1, 1 << 32))
    words.append(0xA << 60)  # EXT_TRIGGER
    return words


w21 = evt21_words()
put('evt21', 'synthetic_genx320.raw', b'% format EVT21;height=320;width=320\n% end\n'
    + b''.join(struct.pack('<Q', w) for w in w21))
put('evt21', 'synthetic_imx636.raw', b'% evt 2.1\n% geometry 1280x720\n% end\n'
    + b''.join(struct.pack('<II', w >> 32, w & 0xFFFFFFFF) for w in w21))
put('evt21', 'header_only.raw', b'% format EVT21;height=320;width=320\n% end\n')

# ---- Prophesee .dat: '%' header, event type and size bytes, 8-byte records.
d = read('prophesee_dat/NCARS_obj_004397_td.dat')
h = text_header_end(d, b'%') + 2
put('prophesee_dat', 'real_head_400ev.dat', d[:h + 400 * 8])
put('prophesee_dat', 'header_only.dat', d[:h])

# ---- RPG text: `t x y p` per line (t in seconds).
d = read('rpg_txt/slider_depth_events_chunk.txt')
lines = d.split(b'\n')
put('rpg_text', 'real_head_150ev.txt', b'\n'.join(lines[:150]) + b'\n')
put('rpg_text', 'synthetic_odd.txt', b'# comment\n0.000001 1 2 1\r\n0.000002 3 4 0\n\n1e-3 5 6 1\n0.002 7 8 0')

# ---- MATLAB v5 .mat: variable `events`, rows [x y p t] (1-based x, y; t in us).
def mat_matrix(name, rows):
    n = len(rows)
    body = b''
    body += struct.pack('<II', 6, 8) + struct.pack('<II', 6, 0)          # miUINT32 flags: mxDOUBLE_CLASS
    body += struct.pack('<II', 5, 8) + struct.pack('<ii', n, 4)          # miINT32 dims
    nm = name.encode()
    body += struct.pack('<II', 1, len(nm)) + nm + b'\0' * (-len(nm) % 8)  # miINT8 name
    vals = [r[c] for c in range(4) for r in rows]                        # column major
    data = struct.pack('<%dd' % len(vals), *vals)
    body += struct.pack('<II', 9, len(data)) + data                      # miDOUBLE
    return struct.pack('<II', 14, len(body)) + body                      # miMATRIX


def mat_file(elements):
    text = b'MATLAB 5.0 MAT-file, evlife fuzz seed'.ljust(116, b' ')
    return text + b'\0' * 8 + struct.pack('<H', 0x0100) + b'IM' + elements


rows, t = [], 1000.0
for i in range(100):
    t += rng.randrange(1, 50)
    rows.append((rng.randrange(1, 129), rng.randrange(1, 129), rng.choice((-1.0, 1.0)), t))
m = mat_matrix('events', rows)
put('mat', 'synthetic_100ev.mat', mat_file(m))
z = zlib.compress(m)
put('mat', 'synthetic_100ev_compressed.mat', mat_file(struct.pack('<II', 15, len(z)) + z))
put('mat', 'synthetic_other_variable_first.mat', mat_file(mat_matrix('junk', rows[:3]) + m))
put('mat', 'real_stripes_head.mat', read('reference/stripes.mat')[:3000])

# ---- DVS128 USB words: little-endian address (bit 15 of byte 1: sync), timestamp
# (bit 15: wrap, bit 14: reset), mixed as a camera sends them.
words = b''
for i in range(300):
    kind = rng.random()
    if kind < 0.03:
        words += struct.pack('<HH', 0, 0x8000)          # wrap
    elif kind < 0.04:
        words += struct.pack('<HH', 0, 0x4000)          # reset
    elif kind < 0.06:
        words += struct.pack('<HH', 0x8000, i * 13 & 0x3FFF)   # sync / external
    else:
        words += struct.pack('<HH', (rng.randrange(128) << 8) | (rng.randrange(128) << 1) | rng.randrange(2),
                             i * 13 & 0x3FFF)
put('dvs128_decoder', 'synthetic_words.bin', bytes([0x35]) + words)
put('dvs128_decoder', 'synthetic_words_unaligned.bin', bytes([0x02]) + words[:-1])

# ---- configuration: the shipped file and small variants.
with open(os.path.join(HERE, '..', '..', 'config', 'evlife.yaml'), 'rb') as f:
    put('config', 'evlife.yaml', f.read())
put('config', 'overrides.txt', b'estimator.window_size=7\nestimator.regularization=false\n'
    b'estimator.sensor.width=240\nestimator.outlier_fraction=0.3\n')
put('config', 'small.yaml', b'estimator:\n  window_size: 5\n  sensor: {width: 346, height: 260}\n'
    b'  seed: 18446744073709551615\n  lambda_decay_per_us: 5e-3\n')

# ---- augmented output (.csv written by `evlife process`; .bin: see the README).
csv = b'x,y,t,p,lifetime,vx,vy,prediction_error\n'
for i in range(50):
    csv += b'%d,%d,%d,%d,%.3f,%.3f,%.3f,%s\n' % (rng.randrange(128), rng.randrange(128), 1000 + 10 * i,
                                              rng.choice((1, -1)), rng.random() * 1e4, rng.random() * 100,
                                              -rng.random() * 100, b'' if i % 3 else b'%.2f' % rng.random())
put('augmented', 'synthetic_50.csv', csv)

# ---- ROS 2 bag messages (tests/fuzz/fuzz_ros_*.cpp): real messages of the shared
# rosbag2 bags; payload seeds = u16 width, u16 height, u64 time_base, u8 cut + payload.
import sqlite3  # noqa: E402


def bag_messages(rel, limit):
    db = sqlite3.connect('file:' + os.path.join(DATA, rel) + '?mode=ro', uri=True)
    rows = db.execute('SELECT data FROM messages ORDER BY timestamp, id LIMIT ?', (limit,)).fetchall()
    db.close()
    return [bytes(r[0]) for r in rows]


def packet_fields(m):
    """(width, height, time_base, payload) of a CDR EventPacket."""
    def align(pos, n):
        return 4 + (pos - 4 + n - 1) // n * n
    pos = 4 + 8
    n, = struct.unpack_from('<I', m, pos)
    pos = align(pos + 4 + n, 4)
    height, width = struct.unpack_from('<II', m, pos)
    pos = align(pos + 8, 8)
    _, time_base = struct.unpack_from('<QQ', m, pos)
    pos += 16
    n, = struct.unpack_from('<I', m, pos)
    pos += 4 + n + 1
    pos = align(pos, 4)
    n, = struct.unpack_from('<I', m, pos)
    return width, height, time_base, m[pos + 4:pos + 4 + n]


for what, rel in (('ros_evt3', 'rosbag/test_data_evt3_trigger/test_data_evt3_trigger_0.db3'),
                  ('ros_libcaer', 'rosbag/test_data_libcaer_rollover/libcaer_rollover_0.db3'),
                  ('ros_mono', 'rosbag/test_data_mono_cd/test_data_mono_cd_0.db3')):
    for i, m in enumerate(bag_messages(rel, 2)):
        width, height, time_base, payload = packet_fields(m)
        put(what, 'real_msg%d.bin' % i, struct.pack('<HHQB', width, height, time_base, 40) + payload[:3000])
    # Whole messages for the message parser (the first one; mono: both are small).
    put('ros_message', what[4:] + '_msg0.bin', b'\x00' + bag_messages(rel, 1)[0])

# libcaer_cmp (no shared bag holds it): words of every code, a vector of rows, ON and OFF;
# header as fuzz_ros_payload.h (640 x 480, time_base 5 ms, cut after word 4).
cmp_words = [0x0001, 0x1003, 0x2005, 0x3807, 0x4810, 0x50A5, 0x2006, 0x3009, 0x1004, 0x4018, 0x5003]
put('ros_libcaer_cmp', 'words.bin', struct.pack('<HHQB', 640, 480, 5000000, 4) +
    b''.join(struct.pack('<H', w) for w in cmp_words))


class Cdr:
    """Little-endian CDR: primitives aligned to their size from byte 4."""
    def __init__(self):
        self.b = bytearray(b'\x00\x01\x00\x00')

    def put(self, fmt, v):
        n = struct.calcsize('<' + fmt)
        self.b += b'\x00' * ((-(len(self.b) - 4)) % n)
        self.b += struct.pack('<' + fmt, v)


arr = Cdr()
for fmt, v in (('i', 1), ('I', 2), ('I', 4)):
    arr.put(fmt, v)
arr.b += b'cam\x00'
for fmt, v in (('I', 180), ('I', 240), ('I', 3)):
    arr.put(fmt, v)
for k in range(3):
    for fmt, v in (('H', 10 + k), ('H', 20 + k), ('i', 3), ('I', 1000 * k), ('B', k & 1)):
        arr.put(fmt, v)
put('ros_message', 'dvs_array.bin', b'\x01' + bytes(arr.b))

# ---- CSV / text layouts of other tools (fuzz_csv_text).
mv = b''.join(b'%d,%d,%d,%d\n' % (rng.randrange(640), rng.randrange(480), rng.randrange(2), 1000 + 7 * i)
              for i in range(40))
put('csv_text', 'metavision_xypt.csv', mv)
put('csv_text', 'header_tab_xytp.csv', b'x\ty\tt\tp\n' + b''.join(
    b'%d\t%d\t%d\t%d\n' % (rng.randrange(346), rng.randrange(260), 50 + 3 * i, rng.randrange(2)) for i in range(40)))
put('csv_text', 'seconds_txyp.csv', b'# t x y p\n' + b''.join(
    b'%.6f,%d,%d,%d\n' % (0.5 + 1e-5 * i, rng.randrange(240), rng.randrange(180), rng.choice((1, -1))) for i in range(40)))
# NumPy's savetxt default (%.18e everywhere): the exponent path of the number parser.
SAVETXT = b't,x,y,p\n' + b''.join(b'%.18e,%.18e,%.18e,%.18e\n' % (1e-6 * (i + 1), 10 + i, 20 + i, i & 1) for i in range(20))
put('csv_text', 'savetxt_txyp.csv', SAVETXT)
put('rpg_text', 'savetxt_txyp.txt', SAVETXT.split(b'\n', 1)[1].replace(b',', b' '))

# ---- NumPy .npy (fuzz_npy): files NumPy wrote (tests/data/npy/make_npy.py),
# cut to their first 40 records (the shape says 40): structured (padded, big-endian, datetime,
# extra fields, versions 2 and 3) and plain N x 4 layouts.
NPY = os.path.join(HERE, '..', 'data', 'npy')
for name in ('structured_i8', 'evlife_read', 'seconds_f8', 'big_endian', 'datetime_ns', 'extra_fields',
             'version3', 'plain_txyp', 'plain_xypt_seconds'):
    with open(os.path.join(NPY, name + '.npy'), 'rb') as f:
        data = f.read()
    header_len = struct.unpack_from('<H' if data[6] == 1 else '<I', data, 8)[0]
    data_at = (10 if data[6] == 1 else 12) + header_len
    record = (len(data) - data_at) // 200
    header = data[:data_at].replace(b'(200,', b'(40, ')  # the shape, padded to the same length
    put('npy', name + '.npy', header + data[data_at:data_at + 40 * record])

# ---- NumPy .npz (fuzz_npz): archives NumPy wrote (tests/data/npy/make_npy.py), as
# they are (a few KB): one array of events or one per column, stored or deflated.
for name in ('events', 'events_compressed', 'columns', 'columns_compressed', 'two_event_arrays'):
    with open(os.path.join(NPY, name + '.npz'), 'rb') as f:
        put('npz', name + '.npz', f.read())
# Cut archives (no end record: read by their local headers), one inside a deflated member whose
# local header states no size (as zipfile leaves it until the member is closed).
with open(os.path.join(NPY, 'columns.npz'), 'rb') as f:
    data = f.read()
put('npz', 'columns_cut.npz', data[:len(data) * 2 // 3])
with open(os.path.join(NPY, 'events_compressed.npz'), 'rb') as f:
    data = bytearray(f.read()[:1000])
struct.pack_into('<III', data, 14, 0, 0xFFFFFFFF, 0xFFFFFFFF)  # CRC, sizes: ZIP64's
struct.pack_into('<QQ', data, 30 + 10 + 4, 0, 0)  # the ZIP64 extra's sizes
put('npz', 'events_compressed_cut_unsized.npz', bytes(data))


def as_piped(archive):
    """The members of `archive` as zipfile writes them to a stream that cannot seek: flag bit 3,
    no sizes in the local headers (their ZIP64 extra says 0), a ZIP64 data descriptor after each
    member's data; cut 10 bytes into the central directory."""
    out, at = bytearray(), 0
    while archive[at:at + 4] == b'PK\x03\x04':
        crc, packed, size, name_len, extra_len = struct.unpack_from('<IIIHH', archive, at + 14)
        header = bytearray(archive[at:at + 30 + name_len + extra_len])
        extra = header[30 + name_len:]
        if extra[:2] == b'\x01\x00':  # numpy's ZIP64 extra: sizes there
            size, packed = struct.unpack_from('<QQ', extra, 4)
            struct.pack_into('<QQ', header, 30 + name_len + 4, 0, 0)
        struct.pack_into('<H', header, 6, struct.unpack_from('<H', header, 6)[0] | 8)
        struct.pack_into('<III', header, 14, 0, 0xFFFFFFFF, 0xFFFFFFFF)
        data_at = at + len(header)
        out += header + archive[data_at:data_at + packed] + struct.pack('<IIQQ', 0x08074b50, crc, packed, size)
        at = data_at + packed
    return bytes(out) + archive[at:at + 10]


with open(os.path.join(NPY, 'columns_compressed.npz'), 'rb') as f:
    put('npz', 'piped_columns_cut.npz', as_piped(f.read()))

# ---- AEDAT 3.1 (fuzz_aedat3): header, polarity packets (one after the 31-bit
# timestamp overflow, one invalid event), an IMU and a special packet.
def aedat3_packet(type_, size, overflow, events):
    return struct.pack('<hhiiiiii', type_, 1, size, 4, overflow, len(events), len(events), len(events)) + b''.join(events)


def aedat3_polarity(x, y, on, ts, valid=True):
    return struct.pack('<Ii', (x << 17) | (y << 2) | (2 if on else 0) | (1 if valid else 0), ts)


a3 = b'#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS346\r\n#!END-HEADER\r\n'
a3 += aedat3_packet(1, 8, 0, [aedat3_polarity(rng.randrange(346), rng.randrange(260), rng.randrange(2) == 1,
                                              1000 + 13 * i, i % 17 != 5) for i in range(60)])
a3 += aedat3_packet(3, 36, 0, [bytes(36)] * 2)
a3 += aedat3_packet(0, 8, 0, [struct.pack('<Ii', 0, 2000)])
a3 += aedat3_packet(1, 8, 1, [aedat3_polarity(3, 4, True, 7)])
put('aedat3', 'synthetic_packets.aedat', a3)
# Special events of every type (2-4, 6-11: external inputs = triggers), one invalid.
a3s = b'#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS346\r\n#!END-HEADER\r\n'
a3s += aedat3_packet(1, 8, 0, [aedat3_polarity(5 + i, 6, i % 2 == 0, 100 + i) for i in range(8)])
a3s += aedat3_packet(0, 8, 0, [struct.pack('<Ii', (0x123 << 8) | (t << 1) | 1, 200 + t) for t in range(19)] +
                     [struct.pack('<Ii', 2 << 1, 300)])
a3s += aedat3_packet(1, 8, 0, [aedat3_polarity(7, 8, True, 400)])
put('aedat3', 'synthetic_special.aedat', a3s)

# ---- AEDAT 2.0 from DAVIS cameras (fuzz_aedat2): DAVIS240C and DAVIS346
# headers, DVS events (jAER packing: raw x = W-1-column, raw y = H-1-row), an
# APS frame corner, one IMU sample (7 words), an external event, a 32-bit
# clock wrap. Its own random generator: the seeds above stay as they were.
drng = random.Random(4321)


def davis_file(chip, w, h):
    head = (b'#!AER-DAT2.0\r\n# HardwareInterface: DAVIS FX3 0002-INI\r\n# AEChip: ' + chip.encode() + b'\r\n')
    recs = []
    t = 0xFFFFF000
    for i in range(48):
        t = (t + 97) & 0xFFFFFFFF
        col, row, on = drng.randrange(w), drng.randrange(h), drng.randrange(2)
        recs.append(((h - 1 - row) << 22) | ((w - 1 - col) << 12) | (on << 11))
        if i == 10:  # APS reset and signal reads of one pixel
            recs += [0x80000000 | (row << 22) | (col << 12) | (c << 10) | drng.randrange(1024) for c in (0, 1)]
        if i == 20:  # IMU sample: codes 0-6, 16-bit values
            recs += [0x80000C00 | (code << 28) | (drng.randrange(65536) << 12) for code in range(7)]
        if i == 30:
            recs.append(0x400)  # external input
    return head + b''.join(struct.pack('>II', a, (0xFFFFF000 + 97 * k) & 0xFFFFFFFF) for k, a in enumerate(recs))


put('aedat2', 'synthetic_davis240c.aedat', davis_file('eu.seebetter.ini.chips.davis.DAVIS240C', 240, 180))
put('aedat2', 'synthetic_davis346b.aedat', davis_file('eu.seebetter.ini.chips.davis.Davis346B', 346, 260))

# ---- AEDAT 2.0 as v2e writes it (fuzz_aedat2): its header lines, no AEChip
# line, DAVIS addresses of a 346 x 260 output (raw x = 345 - x, raw y = 259 - y),
# events only. Its own random generator.
vrng = random.Random(2468)
v2e_head = (b'#!AER-DAT2.0\r\n# This is a raw AE data file created by AEDat2Output in v2e (see '
            b'https://github.com/SensorsINI/v2e) as specified at '
            b'https://inivation.com/support/software/fileformat/#aedat-20\r\n'
            b'# Data format is int32 address, int32 timestamp (8 bytes total), repeated for each event\r\n'
            b'# Timestamps tick is 1 us\r\n')
v2e_recs = []
for i in range(40):
    x, y, on = vrng.randrange(346), vrng.randrange(260), vrng.randrange(2)
    v2e_recs.append(struct.pack('>II', ((345 - x) << 12) | ((259 - y) << 22) | (on << 11), 1000 + 33 * i))
put('aedat2', 'v2e_346x260.aedat', v2e_head + b''.join(v2e_recs))

# ---- h5py's LZF chunks (fuzz_hdf5_lzf): 4 bytes of the stated chunk size
# (little-endian; 0 = not stated), then an LZF stream built by hand from the
# format's two record kinds: a literal run (control byte < 32: that many + 1
# bytes follow) and a back reference (length - 2 in the control byte's top 3
# bits, 7 = one more length byte; then the offset - 1, 13 bits).


def lzf_literal(data):
    return b''.join(bytes([len(data[i:i + 32]) - 1]) + data[i:i + 32] for i in range(0, len(data), 32))


def lzf_reference(offset, length):
    n, o = length - 2, offset - 1
    if n < 7:
        return bytes([(n << 5) | (o >> 8), o & 0xFF])
    return bytes([(7 << 5) | (o >> 8), n - 7, o & 0xFF])


def lzf_seed(stated, stream):
    return struct.pack('<I', stated) + stream


# A u32 column of DSEC-like x values: 4 distinct rows, then repeats (a long reference).
column = b''.join(struct.pack('<I', v) for v in (17, 18, 19, 20))
column_stream = lzf_literal(column) + lzf_reference(16, 240)
put('hdf5_lzf', 'column_256b.bin', lzf_seed(256, column_stream))
put('hdf5_lzf', 'column_no_size.bin', lzf_seed(0, column_stream))
put('hdf5_lzf', 'short_refs_64b.bin', lzf_seed(64, lzf_literal(bytes(range(16))) + lzf_reference(8, 5) +
                                             lzf_reference(16, 8) + lzf_literal(bytes(range(35)))))

# ---- rosbag2 with message compression (fuzz_rosbag2): the mono bag with each
# message a zstd frame of one stored block (built by hand from the zstd format:
# magic, a single-segment frame header stating the size, a raw last block).


def zstd_stored_frame(data):
    n = len(data)
    assert n < 256 + 65536 and n < 128 * 1024
    header = bytes([0x20, n]) if n < 256 else bytes([0x60]) + struct.pack('<H', n - 256)
    return b'\x28\xb5\x2f\xfd' + header + struct.pack('<I', (n << 3) | 1)[:3] + data


def zstd_messages_bag(rel, out_name):
    import shutil
    out = os.path.join(CORPUS, 'rosbag2', out_name)
    shutil.copyfile(os.path.join(DATA, rel), out)
    db = sqlite3.connect(out)
    for rowid, data in db.execute('SELECT id, data FROM messages').fetchall():
        db.execute('UPDATE messages SET data = ? WHERE id = ?', (zstd_stored_frame(bytes(data)), rowid))
    db.commit()
    db.execute('VACUUM')
    db.close()


zstd_messages_bag('rosbag/test_data_mono_cd/test_data_mono_cd_0.db3', 'mono_cd_zstd_messages.db3')


def ros1_records(data, pos):
    """(offset, header fields, data) of the ROS 1 records from `pos` on."""
    while pos < len(data):
        hlen, = struct.unpack_from('<I', data, pos)
        header, fields, i = data[pos + 4:pos + 4 + hlen], {}, 0
        while i < hlen:
            n, = struct.unpack_from('<I', header, i)
            name, value = header[i + 4:i + 4 + n].split(b'=', 1)
            fields[name], i = value, i + 4 + n
        dlen, = struct.unpack_from('<I', data, pos + 4 + hlen)
        yield pos, fields, data[pos + 8 + hlen:pos + 8 + hlen + dlen]
        pos += 8 + hlen + dlen


def ros1_header(fields):
    body = b''.join(struct.pack('<I', len(k) + 1 + len(v)) + k + b'=' + v for k, v in fields.items())
    return struct.pack('<I', len(body)) + body


def interrupted_ros1_bag(src, out_name):
    """The bag as a recording that stopped before close() leaves it: index_pos 0, no index, the
    last chunk with placeholder sizes (0) followed by its records to the file's end."""
    data = open(os.path.join(HERE, '..', 'data', 'ros1', src), 'rb').read()
    records = list(ros1_records(data, 13))
    header_at, header_fields, header_data = records[0]
    index_pos, = struct.unpack('<Q', header_fields[b'index_pos'])
    chunks = [(at, f, d) for at, f, d in records if f[b'op'] == b'\x05' and at < index_pos]
    last_at, last_fields, last_data = chunks[-1]
    assert last_fields[b'compression'] == b'none'
    out = data[:header_at] + ros1_header({**header_fields, b'index_pos': struct.pack('<Q', 0)})
    out += struct.pack('<I', len(header_data)) + header_data + data[records[1][0]:last_at]
    out += ros1_header({**last_fields, b'size': struct.pack('<I', 0)}) + struct.pack('<I', 0) + last_data
    put('rosbag1', out_name, out)


interrupted_ros1_bag('mono_dvs.bag', 'mono_dvs_interrupted.bag.active')


def zstd_streamed_frame(data, piece=4096):
    """A zstd frame as a streaming compressor ends it (rosbag2's file compression): no content
    size in its header, a 128 KiB window, here raw blocks of `piece` bytes."""
    out = b'\x28\xb5\x2f\xfd' + bytes([0x00, 7 << 3])
    for at in range(0, len(data), piece):
        block = data[at:at + piece]
        last = 1 if at + piece >= len(data) else 0
        out += struct.pack('<I', last | (len(block) << 3))[:3] + block
    return out


put('rosbag2_zstd', 'mono_cd.db3.zstd', zstd_streamed_frame(read('rosbag/test_data_mono_cd/test_data_mono_cd_0.db3')))
