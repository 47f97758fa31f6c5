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
