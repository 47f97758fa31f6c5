"""evlife.read / evlife.open on every input format, against the command line."""
import shutil
import sqlite3
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import evlife
from conftest import RECORDINGS, assert_same_events, cli, cli_bin, data


def test_event_dtype_is_the_contract():
    d = evlife.EVENT_DTYPE
    assert d.names == ("t", "x", "y", "p")
    assert [d[f] for f in d.names] == [np.dtype("<i8"), np.dtype("<u2"), np.dtype("<u2"), np.dtype("i1")]
    assert d.itemsize == 16
    assert evlife.AUGMENTED_DTYPE.names == ("t", "x", "y", "p", "lifetime", "vx", "vy",
                                            "prediction_error")
    assert evlife.AUGMENTED_DTYPE.itemsize == 32


@pytest.mark.parametrize("fmt", sorted(RECORDINGS))
def test_read_every_format_equals_the_cli_input_fields(fmt, tmp_path):
    path = data(RECORDINGS[fmt])
    events = evlife.read(path)
    expected, _ = cli_bin(tmp_path, path)  # the CLI copies t, x, y, p of every event as read
    assert len(events) > 1000
    assert_same_events(events, expected, ["t", "x", "y", "p"])
    assert set(np.unique(events["p"])) <= {-1, 1}
    with evlife.open(path) as r:
        assert r.format == fmt


def test_read_hdf5_made_by_the_cli(tmp_path):
    src = data(RECORDINGS["rpg-text"])
    h5 = tmp_path / "slider.h5"
    cli("convert", src, h5)
    assert_same_events(evlife.read(h5), evlife.read(src), ["t", "x", "y", "p"])
    with evlife.open(h5) as r:
        assert r.format == "hdf5"


HDF5_SEEDS = Path(__file__).resolve().parents[2] / "tests" / "fuzz" / "corpus" / "hdf5"


@pytest.mark.parametrize("layout, name, t_us", [
    # The seeds' 30 events (tests/fuzz/make_hdf5_seeds.cpp): event i at x = 7i mod 346 (240 for
    # event_utils, 1280 for M3ED), y = 5i mod 260 (180, 720), p = +1 for odd i, 37 µs apart.
    ("v2e", "v2e_30ev.h5", 1000),                     # events: N×4 uint32 t µs, x, y, p 0/1
    ("mvsec", "mvsec_30ev.h5", 1_504_645_177_000_000),  # davis/left/events: N×4 float64 x, y, t s, p ±1
    ("event_utils", "event_utils_30ev.h5", 250_000),  # events/xs, ys int16, ts float64 s, ps 0/1
    ("event_utils", "event_utils_bool_30ev.h5", 250_000),  # ps as h5py writes numpy's bool: an enum
    ("m3ed", "m3ed_30ev.h5", 1000),                   # prophesee/left/{x,y,t,p} + calib/resolution
])
def test_read_hdf5_layouts_of_other_tools(layout, name, t_us):
    i = np.arange(30)
    width, height = {"event_utils": (240, 180), "m3ed": (1280, 720)}.get(layout, (346, 260))
    events = evlife.read(HDF5_SEEDS / name)
    np.testing.assert_array_equal(events["t"], t_us + 37 * i)
    np.testing.assert_array_equal(events["x"], (7 * i) % width)
    np.testing.assert_array_equal(events["y"], (5 * i) % height)
    np.testing.assert_array_equal(events["p"], np.where(i % 2 == 1, 1, -1))
    with evlife.open(HDF5_SEEDS / name) as r:
        assert (r.format, r.layout) == ("hdf5", layout)
        if layout == "m3ed":
            assert r.sensor == (1280, 720)  # its calib/resolution


def test_savetxt_of_read_events_reads_back(tmp_path):
    # NumPy's default savetxt: every column as %.18e (seconds 1.000000000000000021e-03,
    # pixels 1.000000000000000000e+01), with or without a header, space or comma.
    events = evlife.read(data(RECORDINGS["rpg-text"]))[:5000]
    columns = np.column_stack([events["t"] / 1e6, events["x"], events["y"], events["p"] > 0])
    for name, kwargs in [("plain.txt", {}), ("header.csv", {"delimiter": ",", "header": "t,x,y,p", "comments": ""})]:
        path = tmp_path / name
        np.savetxt(path, columns, **kwargs)
        assert_same_events(evlife.read(path), events, ["t", "x", "y", "p"])


def test_np_save_of_read_events_reads_back(tmp_path):
    # What a NumPy user keeps: np.save of evlife.read's array, of a re-typed copy, of
    # an N x 4 column stack; the command line reads the same file alike.
    events = evlife.read(data(RECORDINGS["rpg-text"]))[:5000]
    retyped = np.zeros(len(events), [("ts", "<f8"), ("x", "<i4"), ("y", "<i4"), ("polarity", "?")])
    retyped["ts"], retyped["x"], retyped["y"], retyped["polarity"] = events["t"] / 1e6, events["x"], events["y"], events["p"] > 0
    stacked = np.column_stack([events["x"], events["y"], events["t"], events["p"] > 0]).astype(np.int64)
    for name, array in [("read.npy", events), ("retyped.npy", retyped), ("stacked.npy", stacked)]:
        path = tmp_path / name
        np.save(path, array)
        assert_same_events(evlife.read(path), events, ["t", "x", "y", "p"])
    processed, _ = cli_bin(tmp_path, tmp_path / "stacked.npy")
    assert_same_events(processed, events, ["t", "x", "y", "p"])


def test_np_savez_of_read_events_reads_back(tmp_path):
    # np.savez / np.savez_compressed: one array of events among others, or one array per column.
    events = evlife.read(data(RECORDINGS["rpg-text"]))[:5000]
    np.savez(tmp_path / "one.npz", events=events, labels=np.arange(3))
    np.savez_compressed(tmp_path / "columns.npz", xs=events["x"], ys=events["y"], ts=events["t"] / 1e6,
                        polarity=events["p"] > 0)
    np.savez(tmp_path / "two.npz", a=events, b=events[:10])
    for name in ("one.npz", "columns.npz"):
        assert_same_events(evlife.read(tmp_path / name), events, ["t", "x", "y", "p"])
    assert_same_events(evlife.read(tmp_path / "two.npz", topic="b"), events[:10], ["t", "x", "y", "p"])
    with pytest.raises(evlife.InputError, match="several arrays of events; --topic NAME chooses one"):
        evlife.read(tmp_path / "two.npz")


def test_time_unit_reads_a_column_in_another_unit(tmp_path):
    events = evlife.read(data(RECORDINGS["rpg-text"]))[:100]
    np.save(tmp_path / "ms.npy", np.column_stack([events["t"], events["x"], events["y"], events["p"] > 0]))
    as_ms = evlife.read(tmp_path / "ms.npy", time_unit="ms")
    np.testing.assert_array_equal(as_ms["t"], events["t"] * 1000)
    with evlife.open(tmp_path / "ms.npy", time_unit="ms") as reader:
        np.testing.assert_array_equal(next(iter(reader))["t"], events["t"] * 1000)
    with pytest.raises(ValueError, match="time_unit: expected"):
        evlife.read(tmp_path / "ms.npy", time_unit="fortnights")


def test_from_and_to_read_what_the_cli_reads(tmp_path):
    """from_s/to_s: seconds after the first event, as --from/--to; an HDF5
    file starts there by a search on t, the others decode up to it."""
    src = data(RECORDINGS["mat"])
    h5 = tmp_path / "stripes.h5"
    cli("convert", src, h5)
    whole = evlife.read(src)
    t0 = int(whole["t"][0])
    keep = (whole["t"] >= t0 + 200_000) & (whole["t"] < t0 + 500_000)
    assert 1000 < keep.sum() < len(whole) // 2
    cut = tmp_path / "cut.h5"
    cli("convert", src, cut, "--from", "0.2", "--to", "500ms")
    for path in (src, h5):
        part = evlife.read(path, from_s=0.2, to_s=0.5)
        assert_same_events(part, whole[keep], ["t", "x", "y", "p"])
        assert_same_events(part, evlife.read(cut), ["t", "x", "y", "p"])
        with evlife.open(path, chunk_events=10_000, from_s=0.2, to_s=0.5) as r:
            assert_same_events(np.concatenate(list(r)), part, ["t", "x", "y", "p"])
    tail = evlife.read(h5, from_s=0.2)
    assert_same_events(tail, whole[whole["t"] >= t0 + 200_000], ["t", "x", "y", "p"])
    with pytest.raises(ValueError, match="from_s"):
        evlife.read(h5, from_s=-1.0)
    with pytest.raises(ValueError, match="to_s must be after from_s"):
        evlife.open(h5, from_s=0.5, to_s=0.2)
    with pytest.raises(ValueError, match=r"to_s must be after from_s \(0 without it\)"):
        evlife.read(h5, to_s=0.0)  # nothing to read: it returned an empty array
    # A helper's findings: the reason given was wrong (1e-7 is after 0; 1e300 is >= 0, and its 301 digits were printed).
    with pytest.raises(ValueError, match=r"^to_s = 1e-07 s rounds to 0 us: 0 or at least 1e-6 \(1 us\)$"):
        evlife.read(h5, to_s=1e-7)
    with pytest.raises(ValueError, match=r"^from_s must be seconds after the first event, in \[0, 1e9\], got 1e\+300$"):
        evlife.read(h5, from_s=1e300)


def test_a_crop_past_the_end_is_warned_of_as_the_cli_does(tmp_path):
    # A review helper's finding: evlife.process(f, from_s=1000.0) returned 0 events without a word,
    # where `evlife process --from 1000` warns "no event of F within --from/--to".
    src = data(RECORDINGS["mat"])
    said = r"no event of %s within from_s/to_s \(seconds after its first event; evlife.scan" % src
    with pytest.warns(RuntimeWarning, match="^evlife.read: " + said):
        assert len(evlife.read(src, from_s=1000.0)) == 0
    with pytest.warns(RuntimeWarning, match="^evlife.process: " + said):
        assert len(evlife.process(src, from_s=1000.0)) == 0
    with pytest.warns(RuntimeWarning, match="^evlife.process_file: " + said):
        assert evlife.process_file(src, tmp_path / "none.bin", from_s=1000.0)["events"] == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a crop that selects events, or no crop: no warning
        assert len(evlife.read(src, from_s=0.2, to_s=0.5)) > 0
        assert len(evlife.process(src, to_s=0.1)) > 0


def test_a_crop_of_open_that_selects_nothing_is_warned_of_as_by_read():
    # Before: `for chunk in evlife.open(f, from_s=1000.0)` (or polarity="on" of an OFF-only file) ended
    # without a chunk or a word, where evlife.read, process and process_file warn.
    src = data(RECORDINGS["mat"])
    said = r"^evlife.open: no event of %s within from_s/to_s \(seconds after its first event" % src
    with pytest.warns(RuntimeWarning, match=said) as caught:
        assert list(evlife.open(src, from_s=1000.0)) == []
    assert len(caught) == 1 and caught[0].filename == __file__  # at the loop's line
    with pytest.warns(RuntimeWarning, match=said) as caught:
        with evlife.open(src, from_s=1000.0) as r:
            assert len(r.read()) == 0
            assert len(r.read()) == 0  # said once
    assert len(caught) == 1 and caught[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a crop that selects events, or none: no warning at the end
        with evlife.open(src, from_s=0.2, to_s=0.5, chunk_events=10_000) as r:
            assert sum(len(c) for c in r) > 0
            assert len(r.read()) == 0
        assert sum(len(c) for c in evlife.open(src, chunk_events=100_000)) > 0


def test_open_yields_bounded_chunks_equal_to_read():
    path = data(RECORDINGS["evt2"])
    whole = evlife.read(path)
    with evlife.open(path, chunk_events=50_000) as r:
        chunks = list(r)
        assert r.sensor is None or len(r.sensor) == 2
    assert all(0 < len(c) <= 50_000 for c in chunks)
    assert len(chunks) == -(-len(whole) // 50_000)
    assert_same_events(np.concatenate(chunks), whole, ["t", "x", "y", "p"])


# A progress thread reads a property while another reads the chunks and the
# main thread closes the reader: the property used the freed reader (a
# segfault in about half of such 3-s runs; now each waits for the reader's
# lock, or raises "the reader is closed"). In a subprocess: a crash fails
# this test, not the whole suite.
RACE = """
import sys, threading, time
import evlife
sys.setswitchinterval(1e-6)
end = time.monotonic() + float(sys.argv[2])
while time.monotonic() < end:
    r = evlife.open(sys.argv[1], chunk_events=500)
    stop = False
    def poll():
        while not stop:
            try:
                r.bytes_consumed
            except ValueError as e:
                assert "the reader is closed" in str(e), e
    def consume():
        try:
            for _ in r:
                pass
        except ValueError as e:
            assert "the reader is closed" in str(e), e
    threads = [threading.Thread(target=poll), threading.Thread(target=consume)]
    for t in threads:
        t.start()
    time.sleep(0.002)
    r.close()
    stop = True
    for t in threads:
        t.join()
"""


def test_a_property_read_while_another_thread_closes_the_reader():
    r = subprocess.run([sys.executable, "-c", RACE, data(RECORDINGS["aedat4"]), "3"],
                       capture_output=True, text=True)
    assert r.returncode == 0, (r.returncode, r.stderr[-2000:])


def test_reader_reports_sensor_and_format():
    with evlife.open(data(RECORDINGS["mat"])) as r:
        assert r.format == "mat"
        assert r.sensor is None  # .mat states no size
        first = r.read(10)
        assert len(first) == 10 and first.dtype == evlife.EVENT_DTYPE
    with evlife.open(data(RECORDINGS["mat"]), sensor=(128, 128)) as r:
        assert r.sensor == (128, 128)


def test_skipped_records_are_counted_as_the_cli_counts_them(tmp_path):
    path = data(RECORDINGS["aedat4"])  # 59 packets of frames and IMU samples beside the events
    line = [l for l in cli("process", path, "-o", tmp_path / "x.bin").stdout.splitlines()
            if "skipped records" in l]
    expected = int(line[0].split()[2])
    assert expected > 0
    assert evlife.scan(path)["skipped_records"] == expected
    assert evlife.process_file(path, tmp_path / "py.bin")["skipped_records"] == expected
    with evlife.open(path) as r:
        for _ in r:
            pass
        assert r.skipped_records == expected


def test_skipped_records_of_a_whole_file_call_are_warned_of(tmp_path):
    # Before: evlife.read and evlife.process of a recording with triggers, IMU samples or frames
    # returned its events without a word of the records they read past; the CLI's summary counts them.
    path = data(RECORDINGS["aedat4"])
    expected = evlife.scan(path)["skipped_records"]
    said = r"%s: %d non-event records of the format skipped" % (path, expected)
    with pytest.warns(RuntimeWarning, match="^evlife.read: " + said) as caught:
        assert len(evlife.read(path)) > 0
    assert len(caught) == 1 and caught[0].filename == __file__  # at the caller's line
    with pytest.warns(RuntimeWarning, match="^evlife.process: " + said):
        assert len(evlife.process(path)) > 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a recording of events only: no warning
        assert len(evlife.read(data(RECORDINGS["evt3"]))) > 0


def test_read_checks_the_given_sensor():
    path = data(RECORDINGS["mat"])
    with pytest.raises(evlife.InputError, match="outside the 64x64 sensor") as e:
        evlife.read(path, sensor=(64, 64))
    assert e.value.event_index >= 0
    assert e.value.partial is not None and len(e.value.partial) == e.value.event_index


def _two_topic_bag(tmp_path):
    """The shared ROS 2 bag with a second event topic holding a copy of its first message."""
    src = data("rosbag/test_data_mono_cd/test_data_mono_cd_0.db3")
    bag = tmp_path / "two_topics.db3"
    shutil.copyfile(src, bag)
    with sqlite3.connect(bag) as db:
        (name, kind), = db.execute("SELECT name, type FROM topics").fetchall()
        db.execute("INSERT INTO topics VALUES (2, '/right/events', ?, 'cdr', '')", (kind,))
        db.execute("INSERT INTO messages (topic_id, timestamp, data) "
                   "SELECT 2, timestamp, data FROM messages WHERE id = (SELECT MIN(id) FROM messages)")
    return src, bag, name


def test_topic_chooses_the_stream_of_a_bag_with_several(tmp_path):
    src, bag, name = _two_topic_bag(tmp_path)
    with pytest.raises(evlife.InputError, match="topic"):  # which of the two: refused with the list
        evlife.read(bag)
    whole = evlife.read(src)
    assert_same_events(evlife.read(bag, topic=name), whole)
    right = evlife.read(bag, topic="/right/events")
    assert 0 < len(right) < len(whole)
    assert_same_events(right, whole[:len(right)])
    with evlife.open(bag, topic="/right/events") as r:
        assert sum(len(chunk) for chunk in r) == len(right)
    # process, process_file and scan read the chosen topic as the CLI's --topic does.
    expected, _ = cli_bin(tmp_path, bag, "--topic", "/right/events")
    assert_same_events(evlife.process(bag, topic="/right/events"), expected)
    out = tmp_path / "right.bin"
    assert evlife.process_file(bag, out, topic="/right/events")["events"] == len(right)
    assert out.read_bytes() == (tmp_path / "two_topics.db3.bin").read_bytes()
    assert evlife.scan(bag, topic="/right/events")["events"] == len(right)
    with pytest.raises(ValueError, match="topic"):
        evlife.read(bag, topic="")
    with pytest.raises(ValueError, match="topic"):
        evlife.process(np.zeros(3, evlife.EVENT_DTYPE), sensor=(4, 4), topic=name)


def test_topic_chooses_the_camera_of_an_mvsec_file():
    left = evlife.read(HDF5_SEEDS / "mvsec_30ev.h5")
    assert_same_events(evlife.read(HDF5_SEEDS / "mvsec_30ev.h5", topic="davis/left/events"), left)
    with pytest.raises(evlife.InputError, match="davis/right/events"):  # the seed has one camera
        evlife.read(HDF5_SEEDS / "mvsec_30ev.h5", topic="davis/right/events")


_WAL_WRITER = r"""
import os, sqlite3, sys
src, dst = sys.argv[1], sys.argv[2]
c = sqlite3.connect(dst, isolation_level=None)
c.execute("PRAGMA journal_mode=WAL")
c.execute("PRAGMA wal_autocheckpoint=0")
c.execute("ATTACH ? AS s", (src,))
for name, sql in c.execute("SELECT name, sql FROM s.sqlite_master WHERE type='table'").fetchall():
    c.execute(sql)
    c.execute("INSERT INTO main.%s SELECT * FROM s.%s" % (name, name))
c.execute("DETACH s")
c.execute("PRAGMA wal_checkpoint(PASSIVE)")
os._exit(0)  # no close: the -wal file stays, as after a crash
"""


def test_a_wal_bag_whose_checkpoint_stopped_reads_whole(tmp_path):
    # rosbag2's WAL mode: a checkpoint cut short leaves the file shorter than
    # its header's page count while the -wal file holds every page; SQLite
    # reads it whole, and the check for a cut database refused it.
    import os
    import struct
    src = data("rosbag/test_data_libcaer_rollover/libcaer_rollover_0.db3")
    dst = tmp_path / "bag_0.db3"
    subprocess.run([sys.executable, "-c", _WAL_WRITER, src, str(dst)], check=True)
    header = dst.read_bytes()[:100]
    page, pages = struct.unpack(">H", header[16:18])[0], struct.unpack(">I", header[28:32])[0]
    os.truncate(dst, pages // 2 * page)
    assert (tmp_path / "bag_0.db3-wal").stat().st_size > 0
    assert_same_events(evlife.read(str(dst)), evlife.read(src))


def test_a_size_the_file_states_wins_over_sensor():
    # The sensor rule of every command: sensor= is for files that state none. It overrode a stated
    # size: events refused as outside a smaller one, a larger one reported as the file's.
    stated = data(RECORDINGS["aedat4"])
    with evlife.open(stated, sensor=(2000, 2000)) as r:
        assert r.sensor == (320, 240)
    assert evlife.read(stated, sensor=(64, 64)).size == evlife.read(stated).size == 111954
    unstated = data("rpg_txt/slider_depth_events_chunk.txt")
    with evlife.open(unstated, sensor=(300, 200)) as r:
        assert r.sensor == (300, 200)
    with pytest.raises(evlife.InputError, match="outside the 64x64 sensor"):
        evlife.read(unstated, sensor=(64, 64))
