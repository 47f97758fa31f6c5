"""Ctrl-C during a long call: evlife.Interrupted (a KeyboardInterrupt) soon,
with what was done kept, as `evlife process` on SIGINT (it was noticed only
after the whole input, and the result was lost)."""
import os
import signal
import threading
import time

import numpy as np
import pytest

import evlife
from conftest import assert_same_events, cli, data


def interrupt_during(call):
    """call() with a SIGINT 50 ms in: the evlife.Interrupted it raised. A
    signal that lands before the call (a busy machine) is retried."""
    for _ in range(5):
        timer = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))
        try:
            timer.start()
            call()
            timer.join()
        except evlife.Interrupted as e:
            timer.join()
            return e
        except KeyboardInterrupt:  # before the call, in Python: not evlife's to say
            timer.join()
    pytest.fail("no SIGINT landed inside the call in 5 tries")


def stripes_tiled(copies):
    """stripes.mat repeated `copies` times, each copy after the last in time."""
    events = evlife.read(data("reference/stripes.mat"))
    span = int(events["t"][-1]) + 1000
    big = np.tile(events, copies)
    big["t"] = np.concatenate([events["t"] + k * span for k in range(copies)])
    return big


def test_an_interrupted_estimator_goes_on_where_it_stopped():
    big = stripes_tiled(12)  # 4.1 M events: seconds of work, 50 ms before the signal
    est = evlife.LifetimeEstimator(sensor=(128, 128))
    e = interrupt_during(lambda: est.process(big))
    assert isinstance(e, KeyboardInterrupt)
    assert 0 < e.events_processed < len(big)  # stopped early (seconds of work, stopped within ~0.2 s)
    assert len(e.partial) == e.events_processed and e.events_written is None
    assert "go on with events[%d:]" % e.events_processed in str(e)
    rest = est.process(big[e.events_processed:])  # the state holds the events processed
    whole = evlife.LifetimeEstimator(sensor=(128, 128)).process(big)
    assert_same_events(np.concatenate([e.partial, rest]), whole)


def test_an_interrupted_file_keeps_what_was_written(tmp_path):
    recording = tmp_path / "large.h5"
    cli("synth", "-q", "--scene", "large", "--duration", "3", "-o", recording)  # 6 M events
    out = tmp_path / "out.bin"
    whole = evlife.process(str(recording))
    e = interrupt_during(lambda: evlife.process_file(str(recording), str(out)))
    assert 0 < e.events_written == e.events_processed < len(whole)
    assert "interrupted; the first %d events were written to %s" % (e.events_written, out) in str(e)
    written, _ = evlife.read_augmented(str(out))
    assert len(written) == e.events_written
    assert_same_events(written, whole[:len(written)])
    e = interrupt_during(lambda: evlife.process(str(recording)))
    assert 0 < len(e.partial) == e.events_processed < len(whole)
    assert_same_events(e.partial, whole[:len(e.partial)])
    # scan() read on to the end, deaf to Ctrl-C (a KeyboardInterrupt came after it). Its pass
    # may end before the signal lands (~60 M events/s here): said at its end.
    e = interrupt_during(lambda: evlife.scan(str(recording)))
    assert e.partial is None and e.events_processed <= len(whole)
    assert "evlife.scan: interrupted after %d events" % e.events_processed in str(e)


def test_a_handler_of_the_users_runs_after_the_call_as_before():
    # It may read the estimator (whose lock the call holds: a handler run
    # inside the call would wait for it for ever) and raise what it likes.
    big = stripes_tiled(6)
    est = evlife.LifetimeEstimator(sensor=(128, 128))
    seen = []

    def handler(signum, frame):
        seen.append(est.stats["events"])
        raise TimeoutError("the user's")

    previous = signal.signal(signal.SIGINT, handler)
    try:
        timer = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))
        with pytest.raises(TimeoutError):
            timer.start()
            est.process(big)
            timer.join()
        timer.join()
    finally:
        signal.signal(signal.SIGINT, previous)
    assert seen and seen[0] in (0, len(big))  # before the call (a busy machine) or after it, never inside


@pytest.fixture(scope="module")
def large_h5(tmp_path_factory):
    recording = tmp_path_factory.mktemp("interrupt") / "large.h5"
    cli("synth", "-q", "--scene", "large", "--duration", "3", "-o", recording)  # 6 M events
    return str(recording)


def test_an_interrupted_read_keeps_the_events_read(large_h5):
    # read() and Reader.read() decoded the whole file deaf to Ctrl-C, then
    # dropped it for a bare KeyboardInterrupt. A signal the machine delivers
    # after the last block (said with the whole result) is tried again.
    whole = evlife.read(large_h5)
    for _ in range(5):
        e = interrupt_during(lambda: evlife.read(large_h5))
        if e.events_processed < len(whole):
            break
    # (0 where the signal came while the file was being opened)
    assert 0 <= len(e.partial) == e.events_processed < len(whole)
    assert "evlife.read: interrupted after %d events of %s" % (e.events_processed, large_h5) in str(e)
    assert np.array_equal(e.partial, whole[:len(e.partial)])
    for _ in range(5):
        reader = evlife.open(large_h5, chunk_events=len(whole))
        e = interrupt_during(reader.read)
        if e.events_processed < len(whole):
            break
        reader.close()
    rest = reader.read(len(whole))  # goes on after the events the exception holds
    reader.close()
    assert e.events_processed == len(e.partial) < len(whole)
    assert np.array_equal(np.concatenate([e.partial, rest]), whole)


@pytest.mark.parametrize("recording", ["stripes", "three events"])
def test_a_daemon_thread_inside_a_call_at_the_scripts_end_does_not_abort_the_process(recording, tmp_path):
    """A daemon thread (a thread pool's worker) mid-call when the script
    ends: taking the GIL back during the interpreter's finalization ended the
    thread by pthread_exit through a noexcept destructor, std::terminate:
    SIGABRT, exit 134, in about 2 runs of 3 (a review helper's finding).
    Then, with finalization checked before taking the GIL, in about 1 run
    of 40-200 still: finalization began while the thread waited for the GIL.
    Short calls (three events) wait for the GIL most often."""
    import subprocess
    import sys
    call = "evlife.read(%r)" % data("reference/stripes.mat")
    if recording == "three events":
        path = tmp_path / "three.txt"
        path.write_text("0.000001 1 1 1\n0.000002 2 2 0\n0.000003 3 3 1\n")
        call = "evlife.read(%r, sensor=(8, 8))" % str(path)
    script = (
        "import threading, time, evlife\n"
        "def loop():\n"
        "    while True:\n"
        "        %s\n"
        "threading.Thread(target=loop, daemon=True).start()\n"
        "time.sleep(0.05)\n" % call)
    for _ in range(10):
        run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                             env=dict(os.environ))
        assert run.returncode == 0, run.stderr


@pytest.mark.parametrize("scene,pixel", [("large", None), ("textured", "dvs")])
def test_an_interrupted_synth_stops_soon(scene, pixel):
    # A review helper's finding: synth ran deaf to Ctrl-C to its end (13 s for "large", duration=60),
    # then the KeyboardInterrupt dropped the scene all the same.
    started = time.monotonic()
    e = interrupt_during(lambda: evlife.synth(scene, duration=60, pixel=pixel))
    assert time.monotonic() - started < 5  # stopped within a slice or a tile of the signal, not at the end
    assert isinstance(e, KeyboardInterrupt) and e.partial is None and e.events_written is None
    assert e.events_processed > 0  # what was generated before the stop (a textured scene's said 0)
    assert "synth: interrupted after %d of the scene's events were generated" % e.events_processed in str(e)


def test_ctrl_c_while_another_threads_call_holds_the_estimator_ends_the_wait():
    # A call waiting for an estimator that another thread's long call holds
    # waited for that call's end, deaf to Ctrl-C (1.4-1.7 s for a signal sent
    # at 0.2 s in a review). Nothing of the waiting call is done. (evlife.Reader
    # waits for its lock the same way, run_locked_unless_interrupted(): the
    # next test.)
    big = stripes_tiled(30)  # 10 M events: seconds of work for the other thread
    est = evlife.LifetimeEstimator(sensor=(128, 128))
    other = threading.Thread(target=est.process, args=(big,))
    other.start()
    try:
        for call, name in [(lambda: est.stats, "stats"), (est.reset, "reset"),
                           (lambda: est.process(big[:10]), "process")]:
            e = interrupt_during(call)
            assert other.is_alive(), "the wait ended with the other call, not with Ctrl-C"
            assert e.events_processed == 0 and (e.partial is None or len(e.partial) == 0), e
            assert ("evlife.LifetimeEstimator.%s: interrupted while another thread's call held the estimator"
                    % name) in str(e)
    finally:
        other.join()
    stats = est.stats  # the other call's alone: not reset, no event of the interrupted calls
    assert stats["events"] == len(big), stats


def test_ctrl_c_while_another_threads_read_holds_the_reader_ends_the_wait(large_h5):
    # evlife.Reader waits for its lock as the estimator does. Another thread reads the whole file in one chunk (~0.2 s idle); Ctrl-C
    # reaches this thread's read while it waits for that one. An attempt in
    # which the other read ended first (a busy machine) is tried again.
    whole_events = len(evlife.read(large_h5))
    for _ in range(10):
        reader = evlife.open(large_h5, chunk_events=whole_events)
        other_read = []
        other = threading.Thread(target=lambda: other_read.append(reader.read()))
        other.start()
        time.sleep(0.005)  # the other read takes the lock first
        timer = threading.Timer(0.02, os.kill, (os.getpid(), signal.SIGINT))
        timer.start()
        waited = None
        try:
            try:
                reader.read(10)
            except evlife.Interrupted as e:
                waited = e
            waiting_then = other.is_alive()
            timer.join()
        except KeyboardInterrupt:  # landed outside the call, in Python: tried again
            timer.join()
            waited = None
        other.join()
        reader.close()
        if waited is not None and waiting_then:
            break
    else:
        pytest.fail("in 10 tries the other thread's read never outlasted the signal")
    assert "evlife.Reader.read: interrupted while another thread's call held the reader" in str(waited), waited
    assert waited.events_processed == 0 and len(waited.partial) == 0
    # Nothing of the interrupted read was taken: the other read got every event.
    assert len(other_read) == 1 and len(other_read[0]) == whole_events


def test_an_interrupted_write_or_augmented_read_keeps_what_was_done(large_h5, tmp_path):
    # Both ran to the end deaf to Ctrl-C (seconds for a CSV of millions of rows).
    augmented = evlife.process(large_h5)[:2_000_000]
    sensor = evlife.scan(large_h5)["sensor"]
    whole_csv = tmp_path / "whole.csv"
    evlife.write(str(whole_csv), augmented, sensor)
    whole, _ = evlife.read_augmented(str(whole_csv))
    cut_csv = tmp_path / "cut.csv"
    for _ in range(5):
        e = interrupt_during(lambda: evlife.write(str(cut_csv), augmented, sensor))
        if e.events_written < len(augmented):
            break
    assert e.events_processed == e.events_written < len(augmented) and e.partial is None
    assert "evlife.write: interrupted after %d of %d events; %s holds the first %d" % (
        e.events_written, len(augmented), cut_csv, e.events_written) in str(e)
    cut, _ = evlife.read_augmented(str(cut_csv))  # flushed: every row written reads back
    assert len(cut) == e.events_written
    assert_same_events(cut, whole[:e.events_written])
    for _ in range(5):
        e = interrupt_during(lambda: evlife.read_augmented(str(whole_csv)))
        if e.events_processed < len(whole):
            break
    assert len(e.partial) == e.events_processed < len(whole)
    assert "evlife.read_augmented: interrupted after %d events of %s" % (e.events_processed, whole_csv) in str(e)
    assert_same_events(e.partial, whole[:e.events_processed])


def test_ctrl_c_ends_a_wait_for_an_output_fifos_reader(tmp_path):
    # A FIFO no reader opens: process_file and write waited in its open for ever, deaf to Ctrl-C
    # (the command line's stop flag is not Python's SIGINT, which only the main thread sees).
    fifo = tmp_path / "out.bin"
    os.mkfifo(fifo)
    e = interrupt_during(lambda: evlife.process_file(data("reference/stripes.mat"), str(fifo)))
    assert "interrupted before %s was opened; nothing written" % fifo in str(e)
    assert e.events_written == 0 and e.events_processed == 0
    augmented = np.zeros(3, evlife.AUGMENTED_DTYPE)
    augmented["p"] = 1
    e = interrupt_during(lambda: evlife.write(str(fifo), augmented, (8, 8)))
    assert "evlife.write: interrupted: " in str(e) and "no reader had opened this FIFO" in str(e)
    assert e.events_processed == 0


def test_ctrl_c_ends_a_wait_for_an_output_fifo_whose_reader_takes_nothing(tmp_path):
    # The reader opens the FIFO but never reads: the default write-behind thread waited for it
    # for ever, deaf to Ctrl-C (only the calling thread's io waits can hear it).
    fifo = tmp_path / "out.bin"
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)
    try:
        # (sensor given: no scan for it, so the signal lands while the FIFO is full)
        e = interrupt_during(lambda: evlife.process_file(data("reference/stripes.mat"), str(fifo), sensor=(128, 128)))
    finally:
        os.close(reader)
    assert "interrupted while writing: %s: stopped while the reader of this FIFO took no data" % fifo in str(e)
    assert "bytes not written" in str(e)
