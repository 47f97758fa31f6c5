"""Named pipes as input (python/evlife/_streams.py): read from a temporary copy, as the command
line reads `-` and pipes; the copy is removed, and errors name the pipe."""
import gc
import os
import tempfile
import threading

import numpy as np
import pytest

import evlife
from conftest import data

SLIDER = "rpg_txt/slider_depth_events_chunk.txt"


@pytest.fixture
def temp_dir(tmp_path, monkeypatch):
    """Where the copies go (tempfile's $TMPDIR), empty at the start."""
    copies = tmp_path / "copies"
    copies.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(copies))
    return copies


def feed(fifo, payload):
    """Writes payload into the named pipe from a thread (its open waits for the reader)."""
    def write():
        with open(fifo, "wb") as out:
            out.write(payload)
    thread = threading.Thread(target=write, daemon=True)
    thread.start()
    return thread


def pipe(tmp_path, payload, name="events.txt"):
    fifo = tmp_path / name
    os.mkfifo(fifo)
    return fifo, feed(fifo, payload)


def test_every_reading_function_takes_a_named_pipe(tmp_path, temp_dir):
    path = data(SLIDER)
    with open(path, "rb") as f:
        payload = f.read()
    want = evlife.read(path)

    fifo, writer = pipe(tmp_path, payload)
    got = evlife.read(fifo)
    writer.join()
    assert np.array_equal(got, want)
    assert list(temp_dir.iterdir()) == []  # the copy is gone

    os.unlink(fifo)
    fifo, writer = pipe(tmp_path, payload)
    assert evlife.process(str(fifo)).tobytes() == evlife.process(path).tobytes()  # NaN errors too
    writer.join()

    os.unlink(fifo)
    fifo, writer = pipe(tmp_path, payload)
    assert evlife.scan(input=fifo)["events"] == evlife.scan(path)["events"]
    writer.join()

    os.unlink(fifo)
    fifo, writer = pipe(tmp_path, payload)
    evlife.process_file(fifo, tmp_path / "from_pipe.bin")
    writer.join()
    evlife.process_file(path, tmp_path / "from_file.bin")
    assert (tmp_path / "from_pipe.bin").read_bytes() == (tmp_path / "from_file.bin").read_bytes()
    assert list(temp_dir.iterdir()) == []


def test_open_keeps_the_copy_while_its_reader_lives(tmp_path, temp_dir):
    path = data(SLIDER)
    with open(path, "rb") as f:
        fifo, writer = pipe(tmp_path, f.read())
    reader = evlife.open(fifo, chunk_events=7000)
    writer.join()
    assert isinstance(reader, evlife.Reader)  # as a file's reader (it was a StreamReader only)
    assert len(list(temp_dir.iterdir())) == 1
    chunks = list(reader)
    assert np.array_equal(np.concatenate(chunks), evlife.read(path))
    assert max(len(c) for c in chunks) <= 7000
    # As Reader.read: a misspelt keyword is named with the one meant (Python's plain message before).
    with pytest.raises(TypeError, match=r"^evlife.Reader.read\(\) got an unexpected keyword argument "
                                        r"'max_event' \(did you mean 'max_events'\?\)$"):
        reader.read(max_event=5)
    del reader, chunks
    gc.collect()
    assert list(temp_dir.iterdir()) == []


def test_a_bad_stream_is_named_not_its_copy(tmp_path, temp_dir):
    fifo, writer = pipe(tmp_path, b"100 1 2 1\n200 3 4 0\n300 5 six 1\n")
    with pytest.raises(evlife.InputError) as e:
        evlife.read(fifo)
    writer.join()
    assert e.value.path == str(fifo)
    assert str(fifo) in str(e.value) and "evlife-stream" not in str(e.value)
    assert e.value.event_index == 2
    assert list(temp_dir.iterdir()) == []

    # From evlife.open: the error of a read, and of the open itself.
    os.unlink(fifo)
    fifo, writer = pipe(tmp_path, b"100 1 2 1\n200 3 4 0\n300 5 six 1\n")
    with evlife.open(fifo) as reader:
        writer.join()
        assert reader.path == str(fifo)
        with pytest.raises(evlife.InputError) as e:
            list(reader)
    assert e.value.path == str(fifo) and "evlife-stream" not in str(e.value)
    assert list(temp_dir.iterdir()) == []  # removed by the end of `with`
    os.unlink(fifo)
    fifo, writer = pipe(tmp_path, b"\x00\x01\x02 not events", name="events.dat")
    with pytest.raises(evlife.InputError) as e:
        evlife.open(fifo)
    writer.join()
    assert e.value.path == str(fifo)
    assert list(temp_dir.iterdir()) == []


def test_a_warning_of_a_pipe_names_the_pipe_at_the_callers_line(tmp_path, temp_dir):
    # A review helper's finding: the RuntimeWarning of a crop that selects nothing named the deleted copy
    # (/tmp/evlife-stream-….txt), and every warning pointed at _streams.py, not at the user's call.
    with open(data(SLIDER), "rb") as f:
        payload = f.read()
    for source in ("pipe", "file"):
        if source == "pipe":
            path, writer = pipe(tmp_path, payload, name="w%d.txt" % len(list(tmp_path.iterdir())))
        else:
            path, writer = data(SLIDER), None
        with pytest.warns(RuntimeWarning) as caught:
            evlife.read(path, from_s=1000.0)
        if writer:
            writer.join()
        assert len(caught) == 1
        assert str(caught[0].message).startswith("evlife.read: no event of %s within from_s/to_s" % path)
        assert caught[0].filename == __file__, caught[0].filename  # this call's line, not _streams.py's
        # evlife.open's reader, at its end (it said nothing before), the same.
        if source == "pipe":
            path, writer = pipe(tmp_path, payload, name="o%d.txt" % len(list(tmp_path.iterdir())))
        with pytest.warns(RuntimeWarning) as caught:
            with evlife.open(path, from_s=1000.0) as r:
                assert list(r) == []
        if writer:
            writer.join()
        assert len(caught) == 1
        assert str(caught[0].message).startswith("evlife.open: no event of %s within from_s/to_s" % path)
        assert caught[0].filename == __file__, caught[0].filename
    assert list(temp_dir.iterdir()) == []


def test_a_warning_of_rejected_events_of_a_pipe_names_the_pipe(tmp_path, temp_dir):
    # The README listed it as a limitation (the warning named the pipe's temporary copy); the per-thread
    # renaming of a pipe's warnings covers it: kept so.
    events = evlife.process(evlife.read(data(SLIDER))[:3000], sensor=(240, 180))
    events["t"][1000:] += 2**62 - int(events["t"][1000]) + 1  # beyond +-2^62 us: rejected
    evlife.write(tmp_path / "far.h5", events, (240, 180))
    fifo, writer = pipe(tmp_path, (tmp_path / "far.h5").read_bytes(), name="far_pipe.h5")
    with pytest.warns(RuntimeWarning) as caught:
        evlife.process(fifo)
    writer.join()
    assert [str(w.message) for w in caught] == [
        "evlife.process: %s: events rejected (labelled noise, lifetime 0): 0 outside the sensor, 0 bad polarity, "
        "2000 time beyond +-2^62 us" % fifo]
    assert list(temp_dir.iterdir()) == []


def test_a_pipe_given_as_input_and_output_is_refused_before_it_is_read(tmp_path, temp_dir):
    # The check compared the output with the copy: the pipe was read, then its open for writing
    # waited for a reader for good (the command line refuses it).
    fifo = tmp_path / "rec.csv"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="is the input file; refusing to overwrite it"):
        evlife.process_file(fifo, fifo, sensor=(20, 7))
    with pytest.raises(ValueError, match="is the input file"):
        evlife.process_file(input=fifo, output=tmp_path / "x" / ".." / "rec.csv")
    assert list(temp_dir.iterdir()) == []


def test_a_regular_file_is_read_in_place(tmp_path, temp_dir):
    path = data(SLIDER)
    with evlife.open(path) as reader:
        assert reader.path == path
        assert list(temp_dir.iterdir()) == []


def test_a_copy_that_fails_names_the_stream_and_leaves_nothing(tmp_path, temp_dir, monkeypatch):
    fifo, writer = pipe(tmp_path, b"100 1 2 1\n" * 1000)

    def full_disk(fd, data):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(os, "write", full_disk)
    with pytest.raises(OSError) as e:
        evlife.read(fifo)
    writer.join()
    assert e.value.errno == 28
    assert str(fifo) in str(e.value) and "after 0 bytes" in str(e.value) and "TMPDIR" in str(e.value)
    assert list(temp_dir.iterdir()) == []


def test_help_says_that_pipes_are_copied():
    for function in (evlife.read, evlife.open, evlife.scan, evlife.process, evlife.process_file):
        assert "named pipe" in function.__doc__ and "$TMPDIR" in function.__doc__, function
        assert function.__doc__.startswith(function.__name__ + "("), function  # the C++ signature line first


def test_sockets_are_streams_too(tmp_path, temp_dir):
    # A socket as stdin (/dev/stdin, /dev/fd/N: open() cannot read one) and a
    # listening socket file: both copied as pipes are (InputError "cannot open" before).
    import socket
    payload = open(data(SLIDER), "rb").read()
    expected = evlife.read(data(SLIDER))
    ours, theirs = socket.socketpair()
    with ours, theirs:
        sender = threading.Thread(target=lambda: (theirs.sendall(payload), theirs.shutdown(socket.SHUT_WR)),
                                  daemon=True)
        sender.start()
        np.testing.assert_array_equal(evlife.read("/dev/fd/%d" % ours.fileno()), expected)
        sender.join()
    path = str(tmp_path / "events.sock")
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(path)
    server.listen(1)

    def serve():
        connection, _ = server.accept()
        with connection:
            connection.sendall(payload)
    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    np.testing.assert_array_equal(evlife.read(path), expected)
    thread.join()
    server.close()
    assert os.listdir(temp_dir) == []


def test_what_is_no_path_is_a_typeerror_and_a_fault_before_any_event_says_none_was_written(tmp_path):
    import io
    with pytest.raises(TypeError, match="expected a path"):
        evlife.scan(io.BytesIO(b"x"))
    with pytest.raises(TypeError, match="expected a path"):
        evlife.process_file(data(SLIDER), io.BytesIO())
    with pytest.raises(TypeError, match="a file object; give its path"):
        evlife.process(io.BytesIO(b"x"))
    with evlife.open(data(SLIDER)) as reader:  # it was called "a file object" too
        with pytest.raises(TypeError, match=r"an evlife.Reader gives a recording chunk by chunk; give the file's "
                                            r"path, or feed its chunks to one evlife.LifetimeEstimator"):
            evlife.process(reader)
    cut = tmp_path / "cut.mat"
    cut.write_bytes(open(data("reference/stripes.mat"), "rb").read()[:700_000])
    with pytest.raises(evlife.InputError) as raised:
        evlife.process_file(cut, tmp_path / "out.bin")
    assert raised.value.events_written == 0
    with pytest.raises(evlife.InputError) as raised:
        evlife.process(cut)
    assert raised.value.partial is not None and raised.value.partial.size == 0
