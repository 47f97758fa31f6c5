"""evlife.process / LifetimeEstimator / process_file: the same results as `evlife process`."""
import errno
import os
import subprocess
import sys

import numpy as np
import pytest

import evlife
from conftest import RECORDINGS, assert_same_events, cli, cli_bin, data


@pytest.mark.parametrize("name", ["reference/stripes.mat", "reference/garfield.mat"])
def test_process_path_equals_cli_bin_on_the_reference_recordings(name, tmp_path):
    path = data(name)
    expected, sensor = cli_bin(tmp_path, path)
    actual = evlife.process(path)
    assert actual.dtype == evlife.AUGMENTED_DTYPE
    assert_same_events(actual, expected)
    assert (actual["lifetime"] > 0).mean() > 0.3  # the recordings have edges: not all noise
    # And the array route: read, then estimate with the CLI's sensor.
    assert_same_events(evlife.process(evlife.read(path), sensor=sensor), expected)


def test_a_time_unit_reaches_the_sensor_scan(tmp_path):
    # A CSV in epoch nanoseconds that states no sensor: the scan for its size read it
    # without time_unit="ns" and failed ("too large for the time unit ... time_unit=").
    path = tmp_path / "epoch_ns.csv"
    with open(path, "w") as f:
        f.write("t,x,y,p\n")
        for i in range(3000):
            f.write("%d,%d,%d,%d\n" % (1_700_000_000_000_000_000 + i * 20_000, i % 20, (i // 20) % 7, i % 2))
    expected, sensor = cli_bin(tmp_path, path, "--time-unit", "ns")
    assert sensor == (20, 7)
    assert_same_events(evlife.process(path, time_unit="ns"), expected)
    out = tmp_path / "py.bin"
    evlife.process_file(path, out, time_unit="ns")
    assert out.read_bytes() == (tmp_path / "epoch_ns.csv.bin").read_bytes()


@pytest.mark.parametrize("fmt", ["aedat4", "evt3", "rpg-text"])
def test_process_other_formats_equal_cli(fmt, tmp_path):
    path = data(RECORDINGS[fmt])
    expected, _ = cli_bin(tmp_path, path)
    assert_same_events(evlife.process(path), expected)


def test_options_reach_the_estimator_as_cli_set(tmp_path):
    path = data("reference/garfield.mat")
    expected, _ = cli_bin(tmp_path, path, "--set", "estimator.window_size=7",
                          "--set", "estimator.regularization=false")
    actual = evlife.process(path, window_size=7, regularization=False)
    assert_same_events(actual, expected)
    # NumPy's scalars as Python's (a mask's element is an np.bool_, which has no __index__).
    assert_same_events(evlife.process(path, window_size=np.int64(7), regularization=np.bool_(False)), expected)
    with pytest.raises(TypeError, match="window_size: expected an integer, got a bool"):
        evlife.process(path, window_size=np.bool_(True))
    default = evlife.process(path)
    assert not np.array_equal(default["lifetime"], actual["lifetime"])


def test_sensor_argument_as_cli_sensor(tmp_path):
    path = data(RECORDINGS["rpg-text"])
    expected, sensor = cli_bin(tmp_path, path, "--sensor", "300x200")
    assert sensor == (300, 200)
    assert_same_events(evlife.process(path, sensor=(300, 200)), expected)


def test_an_array_takes_the_configured_sensor_as_the_cli_does(tmp_path):
    # sensor=, else estimator.sensor of config=, else the events' size: the
    # array used the events' size over the configured one (an event outside a
    # configured 64x64 passed, and a 300x300 run differed from the CLI's).
    path = data(RECORDINGS["rpg-text"])
    events = evlife.read(path)
    for side in (64, 300):
        config = tmp_path / ("s%d.yaml" % side)
        config.write_text("estimator:\n  sensor: {width: %d, height: %d}\n" % (side, side))
        if side == 64:
            with pytest.raises(evlife.InputError, match="outside the 64x64 sensor"):
                evlife.process(events, config=config)
            continue
        expected, sensor = cli_bin(tmp_path, path, "--config", config)
        assert sensor == (300, 300)
        assert_same_events(evlife.process(events, config=config), expected)
    assert_same_events(evlife.process(events, sensor=(300, 300), config=tmp_path / "s64.yaml"),
                       evlife.process(events, sensor=(300, 300)))  # sensor= first


def test_rejected_events_of_a_recording_are_counted_as_the_cli_counts_them(tmp_path):
    # Times beyond +-2^62 us: labelled noise unexamined. evlife.process(PATH)
    # and process_file said nothing of them; the CLI prints "rejected".
    events = evlife.process(evlife.read(data(RECORDINGS["rpg-text"]))[:3000], sensor=(240, 180))
    events["t"][1000:] += 2**62 - int(events["t"][1000]) + 1
    h5 = tmp_path / "far.h5"
    evlife.write(h5, events, (240, 180))  # its t, x, y, p: a recording
    summary = cli("process", h5, "-o", tmp_path / "cli.bin").stdout
    assert "rejected            0 outside the sensor, 0 bad polarity, 2000 time beyond +-2^62 us" in summary
    r = evlife.process_file(h5, tmp_path / "py.bin")
    assert r["rejected"] == {"out_of_sensor": 0, "bad_polarity": 0, "time_out_of_range": 2000}
    with pytest.warns(RuntimeWarning, match=r"far.h5: events rejected \(labelled noise, lifetime 0\): "
                                            r"0 outside the sensor, 0 bad polarity, 2000 time beyond"):
        out = evlife.process(h5)
    assert len(out) == 3000 and (out["lifetime"][1000:] == 0).all()
    assert evlife.process_file(data(RECORDINGS["rpg-text"]), tmp_path / "ok.bin")["rejected"] == {
        "out_of_sensor": 0, "bad_polarity": 0, "time_out_of_range": 0}


def test_process_path_gives_the_cli_bytes_record_for_record(tmp_path):
    # Every byte of the records, padding included, whatever buffers held
    # before (the reader thread's are reused and not zeroed): three calls.
    path = data(RECORDINGS["aedat2"])
    cli("process", path, "-o", tmp_path / "cli.bin", "-q")
    expected = (tmp_path / "cli.bin").read_bytes()[32:]
    for _ in range(3):
        assert evlife.process(path).tobytes() == expected


def test_process_file_writes_the_cli_bytes(tmp_path):
    path = data("reference/stripes.mat")
    cli("process", path, "-o", tmp_path / "cli.bin", "-q")
    info = evlife.process_file(path, tmp_path / "py.bin")
    assert (tmp_path / "py.bin").read_bytes() == (tmp_path / "cli.bin").read_bytes()
    assert info["events"] > 0 and info["format"] == "mat"
    aug, sensor = evlife.read_augmented(tmp_path / "py.bin")
    assert sensor == info["sensor"]
    assert_same_events(aug, evlife.process(path))


def test_read_augmented_reads_every_output_format_as_written(tmp_path):
    # .h5 too (it raised "not an augmented CSV"): the records bit for bit, the sensor the file states.
    path = data("reference/garfield.mat")
    expected = evlife.process(path)
    for ext in ("bin", "csv", "h5"):
        evlife.process_file(path, tmp_path / f"g.{ext}")
        back, sensor = evlife.read_augmented(tmp_path / f"g.{ext}")
        assert sensor == (None if ext == "csv" else (128, 128)), ext
        assert back.dtype == expected.dtype and back.tobytes() == expected.tobytes(), ext
    evlife.write(tmp_path / "events.h5", expected[:0], sensor=(128, 128))  # no record: still augmented
    assert len(evlife.read_augmented(tmp_path / "events.h5")[0]) == 0
    cli("convert", path, tmp_path / "plain.h5", "-q")  # events without lifetimes
    with pytest.raises(evlife.InputError, match="without evlife's lifetime"):
        evlife.read_augmented(tmp_path / "plain.h5")


def test_read_augmented_of_a_recording_says_it_is_one():
    # Before: read_augmented("stripes.mat") (or an .aedat4, an np.save'd .npy) raised "not an augmented CSV:
    # the first line must be 'x,y,t,p,lifetime,...'", naming a format the file never claimed to be.
    for name in ("mat", "aedat4", "rpg-text"):
        path = data(RECORDINGS[name])
        with pytest.raises(evlife.InputError) as e:
            evlife.read_augmented(path)
        assert str(e.value).startswith(
            "%s: a recording (%s), not evlife's output: evlife.read reads its events, evlife.process estimates "
            "them; read_augmented reads the .bin, .csv or .h5 that `evlife process -o` and evlife.write write"
            % (path, name)), str(e.value)
        assert e.value.path == path and e.value.partial is None


@pytest.mark.parametrize("ext", ["bin", "csv", "h5"])
def test_process_file_on_one_thread_writes_the_same_bytes(ext, tmp_path):
    # Decoding ahead and writing behind change when the work is done, not what
    # is written (the default runs three threads, one_thread=True one).
    path = data("reference/garfield.mat")
    overlapped = evlife.process_file(path, tmp_path / f"over.{ext}")
    alone = evlife.process_file(path, tmp_path / f"one.{ext}", one_thread=True)
    assert overlapped == alone and overlapped["events"] > 100_000
    assert (tmp_path / f"over.{ext}").read_bytes() == (tmp_path / f"one.{ext}").read_bytes()
    assert_same_events(evlife.process(path, one_thread=True), evlife.process(path))


def test_process_file_reports_a_full_disk_and_stops(tmp_path):
    # The writer's error surfaces from the writing thread at the next hand-over
    # or at close: either way the call raises, naming the output.
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full")
    full = tmp_path / "full.bin"
    os.symlink("/dev/full", full)
    for one_thread in (False, True):
        with pytest.raises(OSError, match="full.bin") as e:
            evlife.process_file(data("reference/garfield.mat"), full, one_thread=one_thread)
        assert e.value.errno == errno.ENOSPC


# An .h5 that cannot be created (a full disk) raises OSError; the program that
# caught it ends as it chooses, without libhdf5's exit noise after it ("HDF5:
# infinite loop closing library" and a line of FL,FL,...: the CLI leaves with
# _Exit, Python printed it). In a subprocess: the noise comes at its exit.
CREATE_ON_FULL_DISK = """
import sys
import numpy as np
import evlife
events = np.zeros(3, evlife.AUGMENTED_DTYPE)
events["t"] = [1, 2, 3]
events["p"] = 1
try:
    evlife.write(sys.argv[1], events, (8, 8))
except OSError as e:
    print("caught:", e)
"""


def test_an_hdf5_file_that_cannot_be_created_leaves_no_library_noise(tmp_path):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full")
    full = tmp_path / "full.h5"
    os.symlink("/dev/full", full)
    r = subprocess.run([sys.executable, "-c", CREATE_ON_FULL_DISK, str(full)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "caught:" in r.stdout and "full.h5" in r.stdout, r.stdout
    assert "infinite loop" not in r.stderr and "FL,FL" not in r.stderr, r.stderr


def test_process_file_never_writes_over_its_input(tmp_path):
    src = tmp_path / "in.csv"
    evlife.process_file(data("reference/garfield.mat"), src)
    before = src.read_bytes()
    os.symlink(src, tmp_path / "link.csv")
    for out in (src, tmp_path / "link.csv"):
        with pytest.raises(ValueError, match="is the input file"):
            evlife.process_file(src, out)
        assert src.read_bytes() == before


def test_chunked_equals_whole():
    events = evlife.read(data("reference/stripes.mat"))
    whole = evlife.LifetimeEstimator(sensor=(128, 128)).process(events)
    est = evlife.LifetimeEstimator(sensor=(128, 128))
    rng = np.random.default_rng(1)
    cuts = np.sort(rng.choice(np.arange(1, len(events)), size=40, replace=False))
    parts = [est.process(c) for c in np.split(events, cuts)] + [est.process(events[:0])]
    assert_same_events(np.concatenate(parts), whole)
    assert est.stats["events"] == len(events)
    reasons = ("noise_few_samples", "noise_unsupported", "noise_unresolved", "out_of_sensor", "bad_polarity",
               "time_out_of_range")
    assert sum(est.stats[k] for k in reasons) == est.stats["noise"] > 0
    est.reset()
    assert_same_events(est.process(events), whole)  # reset forgets everything


def test_joined_chunks_and_slices_are_written_as_the_whole(tmp_path):
    # np.concatenate of process()'s chunks drops the dtype's padding (29-byte records) and a
    # slice is strided: write() takes both, as frame() does (it refused them with a TypeError).
    events = evlife.read(data("reference/stripes.mat"))[:50000]
    est = evlife.LifetimeEstimator(sensor=(128, 128))
    joined = np.concatenate([est.process(events[:20000]), est.process(events[20000:])])
    assert joined.dtype != evlife.AUGMENTED_DTYPE
    whole = evlife.process(events, sensor=(128, 128))
    evlife.write(tmp_path / "joined.bin", joined, (128, 128))
    evlife.write(tmp_path / "whole.bin", whole, (128, 128))
    assert (tmp_path / "joined.bin").read_bytes() == (tmp_path / "whole.bin").read_bytes()
    evlife.write(tmp_path / "every_other.csv", whole[::2], (128, 128))
    back, _ = evlife.read_augmented(tmp_path / "every_other.csv")
    assert_same_events(back, whole[::2])
    with pytest.raises(TypeError, match="missing field"):
        evlife.write(tmp_path / "plain.bin", events, (128, 128))


def test_any_array_with_t_x_y_p_and_every_polarity_convention():
    events = evlife.read(data("reference/garfield.mat"))
    expected = evlife.process(events, sensor=(128, 128))
    on = events["p"] > 0
    variants = {
        "01": {"t": events["t"], "x": events["x"].astype(np.int64),
               "y": events["y"].astype(np.int32), "p": on.astype(np.uint8)},
        "bool": {"t": events["t"], "x": events["x"], "y": events["y"], "p": on},
    }
    other = np.zeros(len(events), dtype=[("p", "i2"), ("y", ">u2"), ("x", "<i4"), ("t", "<u8"),
                                         ("extra", "f8")])
    for f in "txyp":
        other[f] = events[f]
    variants["other structured"] = other
    variants["strided view"] = np.zeros(len(events), dtype=evlife.AUGMENTED_DTYPE)
    for f in "txyp":
        variants["strided view"][f] = events[f]
    for name, v in variants.items():
        assert_same_events(evlife.process(v, sensor=(128, 128)), expected), name
    # Bytes a NumPy copy left in the padding do not reach the output's bytes.
    junk = np.frombuffer(events.tobytes(), np.uint8).copy().reshape(-1, 16)
    junk[:, 13:] = 0xA5
    assert evlife.process(junk.reshape(-1).view(evlife.EVENT_DTYPE), sensor=(128, 128)).tobytes() == \
        expected.tobytes()


def test_estimator_options_are_the_cli_defaults():
    est = evlife.LifetimeEstimator(sensor=(128, 128))
    table = evlife.estimator_options()
    assert est.options == {k: v["default"] for k, v in table.items()}
    est7 = evlife.LifetimeEstimator(sensor=(128, 128), window_size=7, seed=7)
    assert est7.options["window_size"] == 7 and est7.options["seed"] == 7
    assert est7.sensor == (128, 128)


def test_process_from_and_to_equal_the_cli(tmp_path):
    """from_s/to_s: `evlife process --from --to` (the estimator starts at
    from_s), on HDF5, which starts there by a search, as on .mat."""
    src = data(RECORDINGS["mat"])
    h5 = tmp_path / "stripes.h5"
    cli("convert", src, h5)
    expected, _ = cli_bin(tmp_path, src, "--from", "0.3", "--to", "0.6")
    cli_file = tmp_path / "stripes.mat.bin"
    assert 1000 < len(expected) < len(evlife.read(src)) // 2
    for path in (src, h5):
        assert_same_events(evlife.process(path, from_s=0.3, to_s=0.6), expected)
        written = tmp_path / "part.bin"
        evlife.process_file(path, written, from_s=0.3, to_s=0.6)
        assert written.read_bytes() == cli_file.read_bytes()
    with pytest.raises(ValueError, match="mask"):
        evlife.process(evlife.read(src), sensor=(128, 128), from_s=0.3)


def test_polarity_selects_the_events_the_cli_polarity_flag_does(tmp_path):
    # The CLI's --polarity had no Python counterpart (a review helper's finding).
    src = data(RECORDINGS["mat"])
    whole = evlife.read(src)
    for polarity, keep in (("on", whole["p"] > 0), ("off", whole["p"] < 0)):
        assert 1000 < keep.sum() < len(whole)
        assert_same_events(evlife.read(src, polarity=polarity), whole[keep], ["t", "x", "y", "p"])
        with evlife.open(src, chunk_events=50_000, polarity=polarity) as r:
            assert_same_events(np.concatenate(list(r)), whole[keep], ["t", "x", "y", "p"])
        expected, _ = cli_bin(tmp_path, src, "--polarity", polarity)
        assert_same_events(evlife.process(src, polarity=polarity), expected)
        written = tmp_path / ("%s.bin" % polarity)
        assert evlife.process_file(src, written, polarity=polarity)["events"] == keep.sum()
        assert written.read_bytes() == (tmp_path / "stripes.mat.bin").read_bytes()
    assert len(evlife.read(src, polarity="both")) == len(whole)
    with pytest.raises(ValueError, match=r"^polarity: expected 'on', 'off' or 'both', got 'ON'$"):
        evlife.read(src, polarity="ON")
    with pytest.raises(ValueError, match="mask on its p"):
        evlife.process(whole, polarity="on")
    off_only = tmp_path / "off.npy"
    np.save(off_only, np.stack([whole["x"], whole["y"], whole["t"], whole["p"]], axis=1)[whole["p"] < 0].astype(np.int64))
    with pytest.warns(RuntimeWarning, match=r"evlife.read: no event of .*off.npy is ON \(polarity='on'\)$"):
        assert len(evlife.read(off_only, polarity="on")) == 0
