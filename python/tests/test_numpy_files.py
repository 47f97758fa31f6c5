"""NumPy files as NumPy writes them, read by evlife.read: the cases a review of the
.npy reader found (each failed before its fix)."""
import numpy as np
import pytest

import evlife

N = 50
T = 1000 + 37 * np.arange(N)
X = np.arange(N) % 20
Y = (3 * np.arange(N)) % 10
ON = np.arange(N) % 3 == 0


def structured(fields, **values):
    a = np.zeros(N, dtype=fields)
    for name, v in values.items():
        a[name] = v
    return a


def check(events, t=T):
    np.testing.assert_array_equal(events["t"], t)
    np.testing.assert_array_equal(events["x"], X)
    np.testing.assert_array_equal(events["y"], Y)
    np.testing.assert_array_equal(events["p"], np.where(ON, 1, -1))


def test_names_ending_in_s_are_no_unit(tmp_path):
    # 'timestamps' was read as 'timestamp' in seconds: times 10^6 too large.
    for name in ("timestamps", "times"):
        np.save(tmp_path / "a.npy", structured([(name, "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "i1")],
                                               **{name: T, "x": X, "y": Y, "p": ON}))
        check(evlife.read(tmp_path / "a.npy"))
    (tmp_path / "a.csv").write_text("timestamps,x,y,p\n" + "".join(
        "%d,%d,%d,%d\n" % row for row in zip(T, X, Y, ON)))
    check(evlife.read(tmp_path / "a.csv"))


def test_a_unit_in_a_latin1_header(tmp_path):
    # np.save writes version 1.0 headers in Latin-1: the micro sign is one byte.
    np.save(tmp_path / "mu.npy", structured([("t (µs)", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "i1")],
                                            **{"t (µs)": T, "x": X, "y": Y, "p": ON}))
    check(evlife.read(tmp_path / "mu.npy"))


def test_not_a_time_is_an_error_after_the_events_before(tmp_path):
    a = structured([("t", "<M8[us]"), ("x", "<u2"), ("y", "<u2"), ("p", "i1")], x=X, y=Y, p=np.where(ON, 1, -1))
    a["t"] = T.astype("M8[us]")
    a["t"][7] = np.datetime64("NaT")
    np.save(tmp_path / "nat.npy", a)
    with pytest.raises(evlife.InputError, match="record 7: its field 't' = .* is NaT, not a time") as e:
        evlife.read(tmp_path / "nat.npy")
    assert len(e.value.partial) == 7


def test_a_fraction_after_the_whole_float_times_that_made_the_unit_us_asks_for_the_unit(tmp_path):
    # Float times, whole in the first rows: µs; a fraction after them was
    # rounded to µs, silently (with fewer whole rows first: all in seconds).
    t = np.arange(1500, dtype="<f8")
    t = np.append(t, 1500.5)
    a = np.zeros(len(t), dtype=[("t", "<f8"), ("x", "<u2"), ("y", "<u2"), ("p", "i1")])
    a["t"] = t
    np.save(tmp_path / "f.npy", a)
    with pytest.raises(evlife.InputError, match="record 1500: its field 't' = 1500.5 is a fraction, but the whole "
                                                "times of the first rows made the unit µs") as e:
        evlife.read(tmp_path / "f.npy")
    assert len(e.value.partial) == 1500
    assert evlife.read(tmp_path / "f.npy", time_unit="s")["t"][-1] == 1_500_500_000


def test_records_larger_than_a_buffer_read(tmp_path):
    # 2.4 MB a record: before, 0 events and no error.
    a = structured([("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "?"), ("blob", "<f8", (300_000,))],
                   t=T, x=X, y=Y, p=ON)[:3]
    np.save(tmp_path / "big.npy", a)
    np.testing.assert_array_equal(evlife.read(tmp_path / "big.npy")["t"], T[:3])


def test_empty_zero_size_and_bool_bytes_as_numpy_reads_them(tmp_path):
    np.save(tmp_path / "empty.npy", np.zeros((0, 4), "<i8"))
    assert len(evlife.read(tmp_path / "empty.npy")) == 0
    np.save(tmp_path / "zero.npy", structured([("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "?"),
                                               ("aux", "<f4", (0,))], t=T, x=X, y=Y, p=ON))
    check(evlife.read(tmp_path / "zero.npy"))
    a = structured([("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "?")], t=T, x=X, y=Y, p=ON)
    a.view(np.uint8).reshape(N, -1)[0, -1] = 2  # True to NumPy (ON[0] is True)
    np.save(tmp_path / "bool.npy", a)
    check(evlife.read(tmp_path / "bool.npy"))


def test_two_columns_of_one_role_are_refused_naming_both(tmp_path):
    np.save(tmp_path / "dup.npy", structured([("X", "<u2"), ("x", "<u2"), ("y", "<u2"), ("t", "<i8"), ("p", "i1")]))
    with pytest.raises(evlife.InputError, match="its fields 'X' and 'x' both name x"):
        evlife.read(tmp_path / "dup.npy")
    (tmp_path / "dup.csv").write_text("t,x,y,p,ts_ms\n1,2,3,1,4\n")
    with pytest.raises(evlife.InputError, match="names t twice"):
        evlife.read(tmp_path / "dup.csv")


def npz_stating_size(path, array, stated_size):
    """One deflated events.npy member whose directory entry states `stated_size` (ZIP64)."""
    import io
    import struct
    import zlib
    buffer = io.BytesIO()
    np.save(buffer, array)
    data = buffer.getvalue()
    packer = zlib.compressobj(6, zlib.DEFLATED, -15)
    packed = packer.compress(data) + packer.flush()
    crc, name = zlib.crc32(data), b"events.npy"
    local = struct.pack("<IHHHHHIIIHH", 0x04034B50, 45, 0, 8, 0, 0, crc, len(packed), len(data), len(name), 0)
    extra = struct.pack("<HHQ", 1, 8, stated_size)
    entry = struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 45, 45, 0, 8, 0, 0, crc, len(packed), 0xFFFFFFFF,
                        len(name), len(extra), 0, 0, 0, 0, 0) + name + extra
    end = struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, 1, 1, len(entry), len(local) + len(name) + len(packed), 0)
    path.write_bytes(local + name + packed + entry + end)


def events_array():
    return structured([("t", "<i8"), ("x", "<u2"), ("y", "<u2"), ("p", "i1")], t=T, x=X, y=Y, p=np.where(ON, 1, -1))


def test_a_stated_size_beyond_the_data_is_refused_not_read_past(tmp_path):
    # 2^64 - 16: before, a heap overflow (or 0 events and no error); 2^40: "bytes follow" that are not there.
    npz_stating_size(tmp_path / "huge.npz", events_array(), 0xFFFFFFFFFFFFFFF0)
    with pytest.raises(evlife.InputError, match="states a size beyond 2\\^62 bytes"):
        evlife.read(tmp_path / "huge.npz")
    npz_stating_size(tmp_path / "big.npz", events_array(), 1 << 40)
    with pytest.raises(evlife.InputError, match="its stated size is [0-9]+ bytes more than its data") as e:
        evlife.read(tmp_path / "big.npz")
    check(e.value.partial)


def test_archives_as_numpy_reads_them(tmp_path):
    import zipfile
    events = events_array()
    # A side array of Python objects is passed over (it made the archive unreadable).
    np.savez(tmp_path / "meta.npz", events=events, meta={"sensor": (240, 180)})
    check(evlife.read(tmp_path / "meta.npz"))
    # Bytes after the end record, as some tools append them.
    np.savez(tmp_path / "trail.npz", events=events)
    with open(tmp_path / "trail.npz", "ab") as f:
        f.write(b"\0" * 16)
    check(evlife.read(tmp_path / "trail.npz"))
    # Two members of one name: the last, as np.load.
    np.savez(tmp_path / "dup.npz", events=events[:10])
    with pytest.warns(UserWarning, match="Duplicate name"):
        with zipfile.ZipFile(tmp_path / "dup.npz", "a") as z, z.open("events.npy", "w") as member:
            np.lib.format.write_array(member, events)
    check(evlife.read(tmp_path / "dup.npz", topic="events"))
    # Arrays of other lengths whose names are columns' (frame times) pass over.
    np.savez(tmp_path / "side.npz", events=events, timestamps=np.arange(5), t=np.arange(3.0))
    check(evlife.read(tmp_path / "side.npz"))
    np.savez(tmp_path / "columns.npz", x=X, y=Y, t=T, p=ON, timestamps=np.arange(7))
    check(evlife.read(tmp_path / "columns.npz"))


def test_a_bad_value_names_its_array(tmp_path):
    bad = events_array()
    bad["p"][30] = 5
    np.savez_compressed(tmp_path / "two.npz", good=events_array(), bad=bad)
    with pytest.raises(evlife.InputError, match="array 'bad.npy': record 30: its field 'p' = 5 is not a polarity") as e:
        evlife.read(tmp_path / "two.npz", topic="bad")
    assert len(e.value.partial) == 30


def test_a_message_naming_a_flag_says_its_keyword(tmp_path):
    np.savez(tmp_path / "two.npz", a=events_array(), b=events_array())
    with pytest.raises(evlife.InputError, match=r"--topic NAME chooses one .*\(in Python --topic is topic=\)$"):
        evlife.read(tmp_path / "two.npz")


def test_a_cut_archive_gives_its_events_before_the_cut(tmp_path):
    np.savez(tmp_path / "whole.npz", events=events_array())
    data = (tmp_path / "whole.npz").read_bytes()
    (tmp_path / "cut.npz").write_bytes(data[:len(data) // 2])
    with pytest.raises(evlife.InputError, match="the archive is cut: it ends at byte %d" % (len(data) // 2)) as e:
        evlife.read(tmp_path / "cut.npz")
    partial = e.value.partial
    assert 0 < len(partial) < N
    assert (partial == evlife.read(tmp_path / "whole.npz")[:len(partial)]).all()


def test_an_archive_written_to_a_pipe_and_cut_gives_every_member(tmp_path):
    # zipfile on a stream that cannot seek puts each member's sizes in a data descriptor after
    # its data: cut inside its central directory, only the first member was found.
    import io

    class Pipe(io.RawIOBase):
        def __init__(self):
            self.data = bytearray()

        def writable(self):
            return True

        def write(self, b):
            self.data += b
            return len(b)

        def seekable(self):
            return False

    for save in (np.savez, np.savez_compressed):
        for arrays in ({"x": X, "y": Y, "t": T, "p": ON}, {"events": events_array()}):
            pipe = Pipe()
            save(pipe, **arrays)
            data = bytes(pipe.data)
            cut = data.find(b"PK\x01\x02") + 10
            (tmp_path / "piped.npz").write_bytes(data[:cut])
            with pytest.raises(evlife.InputError, match="cut inside its central directory") as e:
                evlife.read(tmp_path / "piped.npz")
            check(e.value.partial)


def test_column_arrays_come_before_an_unnamed_n_by_4_array(tmp_path):
    # Bounding boxes are N x 4 too: they were read as the events.
    np.savez(tmp_path / "boxes.npz", x=X, y=Y, t=T, p=ON, boxes=np.array([[1, 2, 3, 1], [5, 2, 3, 0]]))
    check(evlife.read(tmp_path / "boxes.npz"))


def test_a_datetime_column_refuses_another_unit(tmp_path):
    a = structured([("t", "<M8[ns]"), ("x", "<u2"), ("y", "<u2"), ("p", "i1")], x=X, y=Y, p=np.where(ON, 1, -1))
    a["t"] = (T * 1000).astype("M8[ns]")
    np.save(tmp_path / "ns.npy", a)
    check(evlife.read(tmp_path / "ns.npy"))
    with pytest.raises(evlife.InputError, match="datetime64, whose type states its unit"):
        evlife.read(tmp_path / "ns.npy", time_unit="us")


def test_a_cut_column_names_the_array_that_ended_the_read(tmp_path):
    import io
    import zipfile

    def npy_bytes(values):
        buffer = io.BytesIO()
        np.save(buffer, values)
        return buffer.getvalue()

    with zipfile.ZipFile(tmp_path / "cut.npz", "w") as z:
        z.writestr("x.npy", npy_bytes(X)[:-8 * 2])  # 48 of 50 values
        z.writestr("y.npy", npy_bytes(Y)[:-8 * 5])  # 45: this one ends the read
        z.writestr("t.npy", npy_bytes(T))
        z.writestr("p.npy", npy_bytes(ON))
    with pytest.raises(evlife.InputError, match="array 'y.npy': the data ends inside record 45") as e:
        evlife.read(tmp_path / "cut.npz")
    assert len(e.value.partial) == 45
