"""Shared helpers of the evlife Python tests (run by ctest as python_tests).

The oracle is the command line: its `.bin` output is read here with NumPy
from the format the README documents, independently of the module.
"""
import os
import subprocess

import numpy as np
import pytest

import evlife

DATA = os.environ.get("EVLIFE_SHARED_DATA_DIR",
                      os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data"))
CLI = os.environ.get("EVLIFE_CLI", "")

# One recording per shared format (HDF5 is made by `evlife convert`).
RECORDINGS = {
    "mat": "reference/stripes.mat",
    "aedat2": "aedat2/alex_walking_again.aedat",
    "aedat4": "aedat4/sample.aedat4",
    "evt2": "evt2/evt2_sample.raw",
    "evt3": "evt3/evt3_sample.raw",
    "prophesee-dat": "prophesee_dat/NCARS_obj_004397_td.dat",
    "rpg-text": "rpg_txt/slider_depth_events_chunk.txt",
}

# The README's NumPy reading of the .bin records (32-byte header first).
BIN_DTYPE = np.dtype([("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "i1"), ("pad", "V3"),
                      ("lifetime", "<f4"), ("vx", "<f4"), ("vy", "<f4"),
                      ("prediction_error", "<f4")])


def data(relative):
    path = os.path.join(DATA, relative)
    if not os.path.exists(path):
        pytest.skip("shared recording missing: " + path)
    return path


def cli(*args, check=True):
    """Runs the evlife command line; returns the CompletedProcess."""
    if not CLI:
        pytest.skip("EVLIFE_CLI not set (run through ctest)")
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError("evlife %s failed (%d): %s" % (" ".join(map(str, args)),
                                                           r.returncode, r.stderr))
    return r


def cli_bin(tmp_path, recording, *args):
    """`evlife process RECORDING -o X.bin ARGS`: (records, sensor) from the file's bytes."""
    out = tmp_path / (os.path.basename(recording) + ".bin")
    cli("process", recording, "-o", out, "-q", *args)
    header = np.fromfile(out, dtype=np.uint8, count=32)
    assert bytes(header[:8]) == b"EVLIFEAE"
    sensor = tuple(int(v) for v in header[16:24].view("<u4"))
    return np.fromfile(out, dtype=BIN_DTYPE, offset=32), sensor


def bits(column):
    """A column as unsigned integers of its size: NaN == NaN, -0.0 != 0.0 (bit equality)."""
    c = np.ascontiguousarray(column)
    return c.view("u%d" % c.dtype.itemsize)


def assert_same_events(actual, expected, fields=None):
    """Bit-identical field by field."""
    fields = fields or [f for f in evlife.AUGMENTED_DTYPE.names if f in expected.dtype.names
                        and f in actual.dtype.names]
    assert len(actual) == len(expected)
    for f in fields:
        diff = np.flatnonzero(bits(actual[f]) != bits(expected[f]))
        assert diff.size == 0, "field %s differs at %d rows, first at %d: %r vs %r" % (
            f, diff.size, diff[0], actual[diff[0]], expected[diff[0]])


def big_events(n, sensor):
    """n events on `sensor` in time order, mostly noise (test_zero_copy's input)."""
    rng = np.random.default_rng(3)
    e = np.empty(n, dtype=evlife.EVENT_DTYPE)
    e["t"] = np.arange(n, dtype=np.int64) // 4
    e["x"] = (np.arange(n) // 7) % sensor[0]
    e["y"] = rng.integers(0, sensor[1], n, dtype=np.uint16)
    e["p"] = np.where(rng.random(n) < 0.5, 1, -1).astype(np.int8)
    return e
