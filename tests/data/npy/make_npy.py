#!/usr/bin/python3
"""Writes the .npy test files of tests/test_io_npy.cpp with NumPy (an independent writer).

Every file holds the same 200 events, event i:
  t = 1000 + 37 * i µs, x = i % 50, y = (7 * i) % 40, ON when i % 3 == 0
in the layouts and types users save them in (np.save of a structured array or of
an N x 4 array), plus files that must be refused or fail part-way:

  structured_i8.npy        x, y, t, p int64 (Tonic's layout), p 0/1
  evlife_read.npy          the dtype evlife.read returns (t i8, x y u2, p i1 = +-1; padded to 16 bytes)
  seconds_f8.npy           ts float64 seconds, x y u2, pol bool (event_utils' names)
  big_endian.npy           x y >i4, t >i8, p >i2
  datetime_ns.npy          t datetime64[ns]
  t_ns.npy                 t_ns int64 nanoseconds (the unit in the name)
  extra_fields.npy         more fields, ignored: a title on x, a string, a sub-array
  version2.npy             format version 2.0
  version3.npy             format version 3.0 (a UTF-8 field name among the others)
  plain_txyp.npy           N x 4 int64, columns t, x, y, p
  plain_xypt_seconds.npy   N x 4 float64, columns x, y, p, t (seconds)
  plain_xytp.npy           N x 4 int32, columns x, y, t, p
  ambiguous.npy            N x 4 of 0 then 1 in every column: several layouts fit
  fortran.npy              N x 4, Fortran order
  five_columns.npy         N x 5
  objects.npy              an object array (pickled)
  no_polarity.npy          fields x, y, t only
  cut.npy                  structured_i8.npy cut inside record 120
  trailing.npy             structured_i8.npy and 5 more bytes
  bad_x.npy                structured_i8.npy with x = -1 at record 50
and NumPy .npz archives (np.savez: stored members; np.savez_compressed: deflated):
  events.npz               structured_i8 as `events`, beside a `labels` array
  events_compressed.npz    the same, compressed
  columns.npz              1-D arrays x, y, t (int64 µs), p (bool)
  columns_compressed.npz   1-D arrays xs, ys, ts (float64 s), polarity, compressed
  two_event_arrays.npz     two arrays of events, `a` and `b` (b: the first 50 events)
  no_events.npz            an image only
  unequal_columns.npz      x, y, p of 200 values, t of 199
  crc.npz                  events.npz with one polarity byte changed (1 -> 0 at record 120): only
                           its CRC-32 tells

  /usr/bin/python3 tests/data/npy/make_npy.py
Deterministic; the checked-in files are its output.
"""
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
N = 200
i = np.arange(N)
T = 1000 + 37 * i
X = i % 50
Y = (7 * i) % 40
ON = i % 3 == 0


def save(name, array, version=None):
    with open(os.path.join(HERE, name), 'wb') as f:
        if version is None:
            np.save(f, array)
        else:
            np.lib.format.write_array(f, array, version=version)


def structured(fields, values):
    a = np.zeros(N, dtype=fields)
    for name, v in values.items():
        a[name] = v
    return a


tonic = structured([('x', '<i8'), ('y', '<i8'), ('t', '<i8'), ('p', '<i8')],
                   {'x': X, 'y': Y, 't': T, 'p': ON.astype(int)})
save('structured_i8.npy', tonic)
evlife_dtype = np.dtype({'names': ['t', 'x', 'y', 'p'], 'formats': ['<i8', '<u2', '<u2', 'i1'],
                         'offsets': [0, 8, 10, 12], 'itemsize': 16})
save('evlife_read.npy', structured(evlife_dtype, {'t': T, 'x': X, 'y': Y, 'p': np.where(ON, 1, -1)}))
save('seconds_f8.npy', structured([('ts', '<f8'), ('x', '<u2'), ('y', '<u2'), ('pol', '|b1')],
                                  {'ts': T / 1e6, 'x': X, 'y': Y, 'pol': ON}))
save('big_endian.npy', structured([('x', '>i4'), ('y', '>i4'), ('t', '>i8'), ('p', '>i2')],
                                  {'x': X, 'y': Y, 't': T, 'p': ON.astype(int)}))
save('datetime_ns.npy', structured([('t', '<M8[ns]'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1')],
                                   {'t': (T * 1000).astype('datetime64[ns]'), 'x': X, 'y': Y, 'p': ON}))
save('t_ns.npy', structured([('t_ns', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1')],
                            {'t_ns': T * 1000, 'x': X, 'y': Y, 'p': ON}))
extra = np.dtype({'names': ['frame', 'x', 'y', 't', 'label', 'aux', 'p'],
                  'formats': ['<i4', '<i2', '<i2', '<i8', '<U4', ('<f4', (2,)), '|i1'],
                  'titles': [None, 'column', None, None, None, None, None]})
save('extra_fields.npy', structured(extra, {'frame': i // 10, 'x': X, 'y': Y, 't': T, 'label': 'edge',
                                            'aux': np.zeros((N, 2)), 'p': ON}))
save('version2.npy', tonic, version=(2, 0))
save('version3.npy', structured([('x', '<i8'), ('y', '<i8'), ('t', '<i8'), ('p', '<i8'), ('\u00e9t\u00e9', '<f4')],
                                {'x': X, 'y': Y, 't': T, 'p': ON.astype(int)}), version=(3, 0))
save('plain_txyp.npy', np.column_stack([T, X, Y, ON]).astype(np.int64))
save('plain_xypt_seconds.npy', np.column_stack([X, Y, ON, T / 1e6]))
save('plain_xytp.npy', np.column_stack([X, Y, T, ON]).astype(np.int32))
STEP = np.repeat([0, 1], N // 2)
save('ambiguous.npy', np.column_stack([STEP, STEP, STEP, STEP]).astype(np.int64))
save('fortran.npy', np.asfortranarray(np.column_stack([T, X, Y, ON]).astype(np.int64)))
save('five_columns.npy', np.column_stack([T, X, Y, ON, ON]).astype(np.int64))
with open(os.path.join(HERE, 'objects.npy'), 'wb') as f:
    np.save(f, np.array([{'x': 1}, None], dtype=object), allow_pickle=True)
save('no_polarity.npy', structured([('x', '<i8'), ('y', '<i8'), ('t', '<i8')], {'x': X, 'y': Y, 't': T}))
whole = open(os.path.join(HERE, 'structured_i8.npy'), 'rb').read()
data_at = len(whole) - N * 32
with open(os.path.join(HERE, 'cut.npy'), 'wb') as f:
    f.write(whole[:data_at + 120 * 32 + 11])
with open(os.path.join(HERE, 'trailing.npy'), 'wb') as f:
    f.write(whole + b'\0' * 5)
bad = tonic.copy()
bad['x'][50] = -1
save('bad_x.npy', bad)

with open(os.path.join(HERE, 'events.npz'), 'wb') as f:
    np.savez(f, events=tonic, labels=np.arange(7))
with open(os.path.join(HERE, 'events_compressed.npz'), 'wb') as f:
    np.savez_compressed(f, events=tonic, labels=np.arange(7))
with open(os.path.join(HERE, 'columns.npz'), 'wb') as f:
    np.savez(f, x=X, y=Y, t=T, p=ON)
with open(os.path.join(HERE, 'columns_compressed.npz'), 'wb') as f:
    np.savez_compressed(f, xs=X.astype(np.uint16), ys=Y.astype(np.uint16), ts=T / 1e6, polarity=ON)
with open(os.path.join(HERE, 'two_event_arrays.npz'), 'wb') as f:
    np.savez(f, a=tonic, b=tonic[:50])
with open(os.path.join(HERE, 'no_events.npz'), 'wb') as f:
    np.savez(f, image=np.zeros((4, 5), np.uint8))
with open(os.path.join(HERE, 'unequal_columns.npz'), 'wb') as f:
    np.savez(f, x=X, y=Y, t=T[:-1], p=ON)
# One polarity byte of record 120 (p is the 4th int64 of a 32-byte record; 1 there, ON) set to 0:
# a plausible OFF event, told only by the member's CRC-32.
zipped = bytearray(open(os.path.join(HERE, 'events.npz'), 'rb').read())
at = zipped.find(tonic.tobytes()[:64])
assert at > 0 and ON[120]
zipped[at + 120 * 32 + 24] = 0
with open(os.path.join(HERE, 'crc.npz'), 'wb') as f:
    f.write(bytes(zipped))
