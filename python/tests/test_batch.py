"""evlife.batch on a Dask LocalCluster of 2 workers: the command line's files."""
import contextlib
import math
import os
import re
import shutil

import numpy as np
import pytest

import evlife
from conftest import RECORDINGS, cli, data

pytest.importorskip("distributed")


def test_local_cluster_of_two_workers_writes_the_cli_files(tmp_path, capsys):
    from evlife import batch
    paths = [data("reference/stripes.mat"), data("reference/garfield.mat"),
             data(RECORDINGS["evt3"]), data(RECORDINGS["aedat2"])]
    # Same file name twice: both kept (names made unique).
    copy = tmp_path / "in" / "stripes.mat"
    copy.parent.mkdir()
    shutil.copy(paths[0], copy)
    bad = tmp_path / "in" / "broken.aedat"
    bad.write_bytes(b"not a recording")
    paths += [str(copy), str(bad)]
    out = tmp_path / "out"
    table = batch.process_files(paths, out, workers=2, window_size=7)

    assert [r.path for r in table] == paths
    assert [r.path for r in table.failed] == [str(bad)]
    assert "broken.aedat" in table.failed[0].error and "unknown event file format" in table.failed[0].error
    # Failed before its output was opened: none written, no output (it named a file never made).
    assert table.failed[0].events == 0 and table.failed[0].output is None
    for row in table[:-1]:
        assert row.error is None and row.events > 0 and 0 < row.lifetime_share <= 1
        expected = tmp_path / ("cli_" + os.path.basename(row.output))
        cli("process", row.path, "-o", expected, "-q", "--set", "estimator.window_size=7")
        assert open(row.output, "rb").read() == expected.read_bytes(), row.path
    assert sorted(os.listdir(out)) == sorted(
        os.path.basename(r.output) for r in table[:-1])
    assert "stripes-2.bin" in os.listdir(out)
    err = capsys.readouterr().err
    assert "6/6" in err and "FAILED" in err  # progress, failure named
    text = str(table)
    assert "broken.aedat" in text and "FAILED" in text


def test_bad_options_fail_before_any_task(tmp_path):
    from evlife import batch
    with pytest.raises(ValueError, match="window_size"):
        batch.process_files([data("reference/stripes.mat")], tmp_path, window_size=4)
    with pytest.raises(TypeError):
        batch.process_files([data("reference/stripes.mat")], tmp_path, windowsize=5)


def test_a_misspelled_keyword_of_a_batch_function_is_named_as_such(tmp_path):
    # Before: process_files(..., worker=3) raised "evlife.LifetimeEstimator() got an unexpected keyword
    # argument 'worker': evlife.LifetimeEstimator: unknown configuration key 'estimator.worker'; keys of ...".
    from evlife import batch
    path = data("reference/stripes.mat")
    cases = [
        (lambda: batch.process_files([path], tmp_path / "o", worker=3), "process_files", "worker", "workers"),
        (lambda: batch.process_files([path], tmp_path / "o", extention=".csv"), "process_files", "extention",
         "extension"),
        (lambda: batch.process_slices(path, tmp_path / "o.bin", slice=3), "process_slices", "slice", "slices"),
        (lambda: batch.process_slices(path, tmp_path / "o.bin", warmup=50), "process_slices", "warmup",
         "warmup_ms"),
    ]
    for call, function, given, meant in cases:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == "evlife.batch.%s() got an unexpected keyword argument '%s' (did you mean '%s'?)" % (
            function, given, meant)
    with pytest.raises(TypeError, match=r"^evlife.batch.process_files\(\) got an unexpected keyword argument "
                                        r"'windowsize'.*did you mean 'estimator.window_size'"):
        batch.process_files([path], tmp_path / "o", windowsize=5)
    with pytest.raises(ValueError, match=r"set at evlife.batch.process_slices\(window_size=4\)"):
        batch.process_slices(path, tmp_path / "o.bin", window_size=4)
    assert not (tmp_path / "o").exists() and not (tmp_path / "o.bin").exists()


def test_a_batch_call_that_does_not_fit_is_said_as_evlifes_functions_say_it(tmp_path):
    # Before: Python's "process_files() missing 2 required positional arguments: 'paths' and 'out_dir'",
    # and for process_files(pths=[...], out_dir=...) "missing 1 required positional argument: 'paths'",
    # naming neither evlife.batch nor the misspelling; evlife.read(pth=p) says both.
    from evlife import batch
    path, o = data("reference/stripes.mat"), tmp_path / "o"
    cases = [
        (lambda: batch.process_files(), "process_files() missing required argument 'paths'"),
        (lambda: batch.process_files([path], window_size=7), "process_files() missing required argument 'out_dir'"),
        (lambda: batch.process_files(pths=[path], out_dir=o),
         "process_files() got an unexpected keyword argument 'pths' (did you mean 'paths'?)"),
        (lambda: batch.process_files([path], outdir=o),
         "process_files() got an unexpected keyword argument 'outdir' (did you mean 'out_dir'?)"),
        (lambda: batch.process_files([path], o, None, 2),
         "process_files() takes from 2 to 3 positional arguments but 4 were given"),
        (lambda: batch.process_files([path], o, out_dir=o),
         "process_files() got multiple values for argument 'out_dir'"),
        (lambda: batch.process_slices(), "process_slices() missing required argument 'path'"),
        (lambda: batch.process_slices(path, slices=3), "process_slices() missing required argument 'output'"),
        (lambda: batch.process_slices(pth=path, output=o),
         "process_slices() got an unexpected keyword argument 'pth' (did you mean 'path'?)"),
        (lambda: batch.process_slices(path, outpt=o),
         "process_slices() got an unexpected keyword argument 'outpt' (did you mean 'output'?)"),
        (lambda: batch.process_slices(path, o, 2, 100.0, None, 2),
         "process_slices() takes from 2 to 5 positional arguments but 6 were given"),
    ]
    for call, message in cases:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value) == "evlife.batch." + message
    # A misspelling is not taken for an argument the call gives (it said "did you mean 'out_dir'?").
    with pytest.raises(TypeError) as e:
        batch.process_files([path], out_dir=o, outdir=o)
    assert str(e.value).startswith("evlife.batch.process_files() got an unexpected keyword argument 'outdir'")
    assert "out_dir" not in str(e.value)
    assert not o.exists()


def test_output_names_are_unique_whatever_the_recordings_are_called():
    from evlife import batch
    names = batch._output_names(["a/g.mat", "b/g.mat", "g-2.dat", "c/G.txt", "g.dat"], ".bin")
    assert len({n.lower() for n in names}) == 5
    assert names[:2] == ["g.bin", "g-2.bin"]


def test_a_folder_given_with_its_slash_names_its_output_and_duplicates_count_on():
    # A rosbag2 folder as the shell completes it ("bag/"): named "recording.bin" before.
    from evlife import batch
    assert batch._output_names(["ds/a/bag/", "ds/b/bag//", "c/events.txt"], ".bin") == [
        "bag.bin", "bag-2.bin", "events.bin"]
    # One name for every sequence: numbered in order (the search for a free number resumes where it
    # stopped: 10,000 took 9 s counting from 2 each time), a recording named events-3 keeps its own.
    names = batch._output_names(["s%d/events.txt" % i for i in range(5)] + ["events-3.txt", "s5/events.txt"], ".bin")
    assert names == ["events.bin", "events-2.bin", "events-3.bin", "events-4.bin", "events-5.bin",
                     "events-3-2.bin", "events-6.bin"]


def test_a_partial_name_fits_where_its_outputs_name_does(tmp_path):
    # The partial's prefix is 25 bytes: an output name of 231..255 bytes failed its row (the command
    # line wrote it) with "File name too long", raised out of the task.
    from evlife import batch
    name_max = os.pathconf(tmp_path, "PC_NAME_MAX")
    stems = ["r" * (name_max - 4 - 1) + c for c in "ab"]  # two names that differ at their end only
    partials = [batch._partial_name(str(tmp_path / (stem + ".bin")), "0123abcd") for stem in stems]
    for partial in partials:
        assert len(os.fsencode(os.path.basename(partial))) <= name_max
        assert os.path.basename(partial).startswith(".evlife-partial-0123abcd.") and partial.endswith(".bin")
        open(partial, "wb").close()  # the file system takes it
    assert partials[0] != partials[1]
    assert batch._partial_name(str(tmp_path / "short.bin"), "0123abcd") == str(tmp_path / ".evlife-partial-0123abcd.short.bin")
    recording = tmp_path / ("r" * (name_max - 4) + ".mat")
    shutil.copy(data("reference/garfield.mat"), recording)
    table = batch.process_files([recording], tmp_path / "out", workers=1, progress=False)
    assert table[0].error is None, table[0].error
    assert os.path.basename(table[0].output) == "r" * (name_max - 4) + ".bin"


def test_outputs_never_take_the_name_of_a_recording_in_the_output_folder(tmp_path):
    from evlife import batch
    (tmp_path / "x.csv").write_text("")
    names = batch._output_names([tmp_path / "x.mat", tmp_path / "x.csv"], ".csv", tmp_path)
    assert names == ["x-2.csv", "x-3.csv"]
    assert batch._output_names(["elsewhere/x.csv"], ".csv", tmp_path) == ["x.csv"]
    # A recording given by a link elsewhere: the file in the folder reserves
    # its own name (rec.h5), not the link's (another recording's rec.h5
    # overwrote it).
    (tmp_path / "rec.h5").write_text("")
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "link.h5").symlink_to(tmp_path / "rec.h5")
    names = batch._output_names([tmp_path / "in" / "link.h5", "in/rec.aedat"], ".h5", tmp_path)
    assert names == ["link.h5", "rec-2.h5"]
    # A link or a hard link in the folder to a file elsewhere: its own name is
    # reserved too (it was given out, and the row failed "is the input file").
    (tmp_path / "in" / "src.h5").write_text("")
    (tmp_path / "soft.h5").symlink_to(tmp_path / "in" / "src.h5")
    os.link(tmp_path / "in" / "src.h5", tmp_path / "hard.h5")
    names = batch._output_names([tmp_path / "soft.h5", tmp_path / "hard.h5"], ".h5", tmp_path)
    assert names == ["soft-2.h5", "hard-2.h5"]


def test_bad_batch_arguments_fail_before_any_task(tmp_path):
    from evlife import batch
    path = data("reference/stripes.mat")
    with pytest.raises(ValueError, match="extension"):
        batch.process_files([path], tmp_path, extension="csv")
    with pytest.raises(ValueError, match="to_s must be after from_s"):
        batch.process_files([path], tmp_path, from_s=0.5, to_s=0.2)
    with pytest.raises(ValueError, match="warmup_ms"):
        batch.process_slices(path, tmp_path / "x.bin", warmup_ms=float("nan"))
    # Before: slices=2.5 raised "'float' object cannot be interpreted as an integer", naming nothing.
    for bad in (2.5, "2", True, 0, -1):
        with pytest.raises(ValueError, match=r"^slices must be a whole number of at least 1, got %s$" % repr(bad)):
            batch.process_slices(path, tmp_path / "x.bin", slices=bad)
    with pytest.raises(ValueError, match="time_unit"):
        batch.process_files([path], tmp_path, time_unit="fortnights")
    # Before: "_check_reader_options(): incompatible function arguments", naming neither function nor argument.
    with pytest.raises(TypeError, match=r"^evlife.batch.process_files\(\): from_s must be a number \(seconds\), "
                                        r"got str '0.5'$"):
        batch.process_files([path], tmp_path, from_s="0.5")
    with pytest.raises(TypeError, match=r"^evlife.batch.process_slices\(\): time_unit must be a str, got int 1$"):
        batch.process_slices(path, tmp_path / "x.bin", time_unit=1)
    with pytest.raises(ValueError, match="polarity: expected 'on', 'off' or 'both', got 'up'"):
        batch.process_files([path], tmp_path, polarity="up")
    # Flags as evlife.process checks them, before the cluster starts (one_thread="no" failed every
    # row, progress="no" printed progress, extension=None raised an AttributeError).
    with pytest.raises(TypeError, match=r"^evlife.batch.process_files\(\): one_thread must be True or False, got str 'no'$"):
        batch.process_files([path], tmp_path, one_thread="no")
    with pytest.raises(TypeError, match=r"^evlife.batch.process_files\(\): progress must be True or False, got str 'no'$"):
        batch.process_files([path], tmp_path, progress="no")
    with pytest.raises(TypeError, match=r"^evlife.batch.process_slices\(\): progress must be True or False, got int 0$"):
        batch.process_slices(path, tmp_path / "x.bin", progress=0)
    with pytest.raises(TypeError, match=r"^evlife.batch.process_files\(\): extension must be a str, got NoneType None$"):
        batch.process_files([path], tmp_path, extension=None)
    with pytest.raises(ValueError, match="time_unit"):
        batch.process_slices(path, tmp_path / "x.bin", time_unit="fortnights")
    # A LocalCluster of no worker would wait for ever.
    for workers in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match="workers must be a whole number of at least 1"):
            batch.process_files([path], tmp_path, workers=workers)
        with pytest.raises(ValueError, match="workers must be a whole number of at least 1"):
            batch.process_slices(path, tmp_path / "x.bin", workers=workers)
        with pytest.raises(ValueError, match="workers must be a whole number of at least 1"):
            batch.local_cluster(workers)  # with it as scheduler, process_files waited for ever
    # The output (or a part) is the recording itself, by another name too: refused before a task
    # (the slices were joined over it, the recording lost), as process_file refuses it.
    recording = tmp_path / "rec.bin"
    shutil.copy(data("prophesee_dat/NCARS_obj_004397_td.dat"), recording)  # a format known by its content
    os.link(recording, tmp_path / "linked.bin")
    before = recording.read_bytes()
    for output in (recording, tmp_path / "linked.bin"):
        with pytest.raises(ValueError, match="is the input file; refusing to overwrite it"):
            batch.process_slices(recording, output, workers=1)
    assert recording.read_bytes() == before


def test_a_time_unit_reaches_every_task(tmp_path):
    # A NumPy file of t in ms: process_files and process_slices read it as `evlife process --time-unit ms`.
    from evlife import batch
    events = evlife.read(data("reference/stripes.mat"))[:20000]
    npy = tmp_path / "ms.npy"
    np.save(npy, np.column_stack([events["t"] // 1000, events["x"], events["y"], events["p"] > 0]))
    expected = tmp_path / "cli.bin"
    cli("process", npy, "-o", expected, "-q", "--time-unit", "ms", "--sensor", "128x128")
    # Paths as bytes, as every other entry point takes them; a NumPy integer of workers.
    table = batch.process_files([os.fsencode(npy)], os.fsencode(tmp_path / "out"), workers=np.int64(1),
                                progress=False, time_unit="ms", sensor=(128, 128))
    assert table[0].error is None, table[0].error
    assert table[0].path == str(npy)
    assert open(table[0].output, "rb").read() == expected.read_bytes()
    assert evlife.scan(npy, time_unit="ms")["t_last"] == int(events["t"][-1] // 1000) * 1000


def test_a_tasks_warning_is_the_callers_at_its_line(tmp_path):
    # A crop past the end: the task's RuntimeWarning, at the line that called
    # process_files (the worker printed it on its stderr at Dask's line).
    import warnings
    from evlife import batch
    with warnings.catch_warnings(record=True) as warned:
        warnings.simplefilter("always", RuntimeWarning)
        table = batch.process_files([data("reference/stripes.mat")], tmp_path / "out", workers=1,
                                    progress=False, from_s=1000.0)
    assert table[0].error is None and table[0].events == 0
    ours = [w for w in warned if "no event of" in str(w.message)]
    assert len(ours) == 1, [str(w.message) for w in warned]
    assert ours[0].category is RuntimeWarning
    assert ours[0].filename == __file__, ours[0].filename


def test_a_polarity_reaches_every_task(tmp_path):
    from evlife import batch
    path = data("reference/stripes.mat")
    expected = tmp_path / "cli.bin"
    cli("process", path, "-o", expected, "-q", "--polarity", "off")
    table = batch.process_files([path], tmp_path / "out", workers=1, progress=False, polarity="off")
    assert table[0].error is None, table[0].error
    assert open(table[0].output, "rb").read() == expected.read_bytes()


def test_a_configuration_from_a_pipe_reaches_every_task(tmp_path):
    # The options' check read the pipe; each task then found it empty and ran with the defaults.
    from evlife import batch
    path = data("reference/garfield.mat")
    cli("process", path, "-o", tmp_path / "w7.bin", "-q", "--set", "estimator.window_size=7")
    for run in ("files", "slices"):
        read_end, write_end = os.pipe()
        os.write(write_end, b"estimator:\n  window_size: 7\n")
        os.close(write_end)
        config = "/proc/self/fd/%d" % read_end
        try:
            if run == "files":
                table = batch.process_files([path], tmp_path / "out", workers=1, config=config, progress=False)
                output = table[0].output
            else:
                output = str(tmp_path / "sl.bin")
                batch.process_slices(path, output, slices=2, warmup_ms=1e7, workers=1, config=config, progress=False)
        finally:
            os.close(read_end)
        assert open(output, "rb").read() == (tmp_path / "w7.bin").read_bytes(), run


def test_time_slices_in_parallel(tmp_path):
    from evlife import batch
    path = data("reference/stripes.mat")
    cli("process", path, "-o", tmp_path / "cli.bin", "-q")
    # A warm-up longer than the recording: every slice's estimator sees the
    # whole past, so the file is the CLI's, byte for byte.
    rows = batch.process_slices(os.fsencode(path), os.fsencode(tmp_path / "full.bin"), slices=3, warmup_ms=1e7,
                                workers=2)  # paths as bytes too
    assert (tmp_path / "full.bin").read_bytes() == (tmp_path / "cli.bin").read_bytes()
    assert len(rows) == 3 and all(r.events > 0 for r in rows)
    assert not [p for p in os.listdir(tmp_path) if ".part" in p]
    # No warm-up: the same events in the same order, estimates near the slice starts differ.
    batch.process_slices(path, tmp_path / "cold.bin", slices=3, warmup_ms=0, workers=2)
    cold, _ = evlife.read_augmented(tmp_path / "cold.bin")
    whole, _ = evlife.read_augmented(tmp_path / "cli.bin")
    for f in "txyp":
        assert (cold[f] == whole[f]).all()
    assert (cold["lifetime"] != whole["lifetime"]).any()
    # The join fails (the output is a folder): an error naming it, and no
    # part file left (the three stayed, 11 MB, and the error named nothing).
    (tmp_path / "taken.bin").mkdir()
    with pytest.raises(OSError, match="taken.bin: cannot join the slices"):
        batch.process_slices(path, tmp_path / "taken.bin", slices=3, workers=2)
    assert not [p for p in os.listdir(tmp_path) if ".part" in p]


def test_slices_reach_an_event_at_the_last_microsecond(tmp_path):
    # A last event at INT64_MAX (labelled noise: beyond +-2^62 us) ended the last slice at t_last + 1,
    # past int64: the task raised TypeError. Now the last slice has no end and the file is the CLI's.
    from evlife import batch
    events = evlife.read(data("prophesee_dat/NCARS_obj_004397_td.dat"))
    events["t"][-1] = 2**63 - 1
    np.save(tmp_path / "tmax.npy", events)
    cli("process", tmp_path / "tmax.npy", "-o", tmp_path / "cli.bin", "-q", "--sensor", "54x61")
    with pytest.warns(RuntimeWarning, match=r"tmax.npy: events rejected .* 1 time beyond \+-2\^62 us$"):
        batch.process_slices(tmp_path / "tmax.npy", tmp_path / "sl.bin", slices=2, warmup_ms=1e19, workers=1,
                             sensor=(54, 61), progress=False)
    assert (tmp_path / "sl.bin").read_bytes() == (tmp_path / "cli.bin").read_bytes()


def test_slices_of_an_hdf5_file_start_at_their_warm_up(tmp_path):
    # HDF5 slices pass the events before their warm-up by a binary search on t
    # instead of decoding them: the same file as slices of the .mat, which
    # decode from the start and drop them.
    from distributed import Client
    from evlife import batch
    path = data("reference/stripes.mat")
    h5 = tmp_path / "stripes.h5"
    cli("convert", path, h5, "-q")
    with batch.local_cluster(2) as cluster, Client(cluster) as client:
        for warmup_ms in (0, 100):
            outputs = []
            for source in (path, h5):
                out = tmp_path / ("%s_%d.bin" % (os.path.basename(source), warmup_ms))
                rows = batch.process_slices(source, out, slices=4, warmup_ms=warmup_ms,
                                            scheduler=client, progress=False)
                assert len(rows) == 4 and all(r.events > 0 for r in rows)
                outputs.append(out.read_bytes())
            assert outputs[0] == outputs[1], warmup_ms


def test_local_cluster_workers_run_without_the_stack_profiler():
    # The housekeeping settings must reach the worker processes, not only
    # this one (they cost the tasks ~15 % of a core each on 2 cores).
    import dask
    from distributed import Client
    from evlife import batch
    with batch.local_cluster(2) as cluster, Client(cluster) as client:
        seen = client.run(lambda: (dask.config.get("distributed.worker.profile.enabled"),
                                   dask.config.get("distributed.worker.memory.monitor-interval")))
    assert len(seen) == 2
    assert all(v == (False, "1s") for v in seen.values()), seen
    assert dask.config.get("distributed.worker.profile.enabled")  # this process keeps Dask's default


def test_a_script_without_the_main_guard_is_refused_not_hung(tmp_path):
    # Dask's spawned workers import the script again: unguarded, each would
    # start a cluster of its own for ever (the script hung, printing tracebacks).
    import subprocess
    import sys
    bag = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "ros1", "mono_dvs.bag")
    call = 'batch.process_files([%r], %r, workers=1, progress=False)' % (bag, str(tmp_path / "out"))
    scripts = {
        "top.py": "from evlife import batch\nprint(%s)\n" % call,
        "in_main.py": "from evlife import batch\ndef main():\n    %s\nmain()\n" % call,
        "guarded.py": "from evlife import batch\ndef main():\n    print(%s)\n"
                      "if __name__ == '__main__':\n    main()\n" % call,
        "in_tuple.py": "from evlife import batch\nif __name__ in ('__main__',):\n    print(%s)\n" % call,
        # Guards as expressions (refused before: only `if` and `match` were recognized).
        "if_expression.py": "from evlife import batch\ndef main():\n    print(%s)\n"
                            "main() if __name__ == '__main__' else None\n" % call,
        "and_guard.py": "from evlife import batch\ndef main():\n    print(%s)\n"
                        "__name__ == '__main__' and main()\n" % call,
    }
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(evlife.__file__)))
    results = {}
    for name, text in scripts.items():
        (tmp_path / name).write_text(text)
        results[name] = subprocess.run([sys.executable, str(tmp_path / name)], env=env, cwd=tmp_path,
                                       capture_output=True, text=True, timeout=120)
    for name, line in (("top.py", 2), ("in_main.py", 4)):
        r = results[name]
        assert r.returncode != 0, name
        assert "%s:%d starts a Dask LocalCluster outside `if __name__ == \"__main__\":`" % (
            tmp_path / name, line) in r.stderr, r.stderr[-2000:]
        assert "Restarting worker" not in r.stderr
    for name in ("guarded.py", "in_tuple.py", "if_expression.py", "and_guard.py"):
        assert results[name].returncode == 0, (name, results[name].stderr[-2000:])
        assert "mono_dvs.bag" in results[name].stdout and " ok" in results[name].stdout, name
    # A package's __main__ run with -m is never imported again by spawn: no guard needed.
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "__init__.py").write_text("")
    (tmp_path / "pkg" / "__main__.py").write_text(scripts["top.py"])
    by_module = subprocess.run([sys.executable, "-m", "pkg"], env=env, cwd=tmp_path,
                               capture_output=True, text=True, timeout=120)
    assert by_module.returncode == 0 and " ok" in by_module.stdout, by_module.stderr[-2000:]
    # From standard input, workers cannot import the script again, guarded or not.
    from_stdin = subprocess.run([sys.executable, "-"], input=scripts["guarded.py"], env=env, cwd=tmp_path,
                                capture_output=True, text=True, timeout=120)
    assert from_stdin.returncode != 0 and "a script read from standard input cannot start" in from_stdin.stderr


def test_repeated_batches_keep_no_descriptors(tmp_path):
    # Dask's loop per synchronous cluster and client was never closed: an epoll
    # and a socket pair per call, until the process ran out of descriptors.
    from evlife import batch
    bag = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "ros1", "mono_dvs.bag")

    def descriptors():
        return len(os.listdir("/proc/self/fd"))

    def settled(limit):
        # the loop thread closes the last comms a moment after the call returns
        import time
        deadline = time.monotonic() + 10
        while descriptors() > limit and time.monotonic() < deadline:
            time.sleep(0.05)
        return descriptors()

    counts = []
    for k in range(5):
        table = batch.process_files([bag], tmp_path / str(k), workers=1, progress=False)
        assert table.failed == []
        counts.append(settled(counts[0] + 2) if counts else descriptors())
    assert counts[-1] - counts[0] < 3, counts  # 12 more after four calls before


def _batch_in_forked_child(args):
    from evlife import batch
    bag, out, address = args
    return [r.error for r in batch.process_files([bag], out, scheduler=address, progress=False)]


def test_a_forked_child_makes_its_own_event_loop(tmp_path):
    # The module's shared loop runs in a thread a forked child does not have:
    # the child's calls waited for ever on it.
    import multiprocessing
    from evlife import batch
    bag = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "ros1", "mono_dvs.bag")
    with batch.local_cluster(1) as cluster:
        address = cluster.scheduler_address
        assert _batch_in_forked_child((bag, str(tmp_path / "parent"), address)) == [None]
        with multiprocessing.get_context("fork").Pool(1) as pool:
            result = pool.apply_async(_batch_in_forked_child, ((bag, str(tmp_path / "child"), address),))
            assert result.get(timeout=120) == [None]


def test_ctrl_c_while_the_cluster_starts_is_interrupted_with_every_row(tmp_path, monkeypatch):
    # The LocalCluster takes a second or more to start; a Ctrl-C then was a bare KeyboardInterrupt
    # (no rows) and the half-started cluster printed an AssertionError at exit. Now the start
    # finishes, the cluster is closed, and Interrupted says of every recording that nothing was
    # written. The signal is sent from inside the start, so it lands there every time.
    import signal
    from evlife import batch
    started = []

    def starting(workers):
        os.kill(os.getpid(), signal.SIGINT)
        cluster = real_local_cluster(workers)
        started.append(cluster)
        return cluster

    real_local_cluster = batch.local_cluster
    monkeypatch.setattr(batch, "local_cluster", starting)
    paths = [data("reference/garfield.mat"), data("reference/stripes.mat")]
    with pytest.raises(evlife.Interrupted) as caught:
        batch.process_files(paths, tmp_path / "out", workers=1, progress=False)
    assert "0 of 2 recordings finished" in str(caught.value)
    assert [r.path for r in caught.value.partial] == paths
    assert all("nothing written" in r.error and r.output is None for r in caught.value.partial)
    assert os.listdir(tmp_path / "out") == []
    assert started and started[0].status.name == "closed"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_caller_that_ignores_ctrl_c_starts_workers_that_ignore_it_too(tmp_path):
    # A script started with `&` by a shell script ignores SIGINT, yet a Ctrl-C reaches its process group:
    # the handler installed while the cluster started was reset to the default in the workers spawned
    # then, which died of it, and the batch waited for ever. Now SIG_IGN stays, and the workers inherit it.
    import signal
    import subprocess
    import sys
    script = tmp_path / "ignoring.py"
    script.write_text(
        "import os, signal\n"
        "from evlife import batch\n"
        "if __name__ == '__main__':\n"
        "    signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
        "    with batch._sigint_deferred():\n"
        "        print(signal.getsignal(signal.SIGINT) is signal.SIG_IGN)\n"
        "    client, to_close = batch._client(None, 1)\n"
        "    pids = client.run(os.getpid)\n"
        "    for pid in pids.values():\n"
        "        mask = [l for l in open('/proc/%d/status' % pid) if l.startswith('SigIgn:')][0].split()[1]\n"
        "        print(bool(int(mask, 16) & (1 << (signal.SIGINT - 1))))\n"
        "    for c in to_close:\n"
        "        c.close()\n")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120,
                          env=dict(os.environ), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["True", "True"], done.stdout + done.stderr


def test_ctrl_c_while_connecting_to_a_cluster_says_nothing_was_submitted(tmp_path, monkeypatch):
    # No task reached the cluster: every row says nothing was written (it said the task "may still
    # run on your cluster").
    from evlife import batch

    def connecting(scheduler, workers):
        raise KeyboardInterrupt

    monkeypatch.setattr(batch, "_client", connecting)
    with pytest.raises(evlife.Interrupted) as caught:
        batch.process_files([data("reference/garfield.mat")], tmp_path / "out", scheduler="tcp://10.255.255.1:8786",
                            progress=False)
    assert all("nothing written" in r.error for r in caught.value.partial), caught.value.partial


def test_ctrl_c_keeps_the_finished_rows_and_removes_cut_outputs(tmp_path):
    # The LocalCluster was closed under its running tasks: their outputs were
    # left cut at a 4 KiB page (a .bin of whole records that reads as a
    # shorter recording), and a bare KeyboardInterrupt lost every row.
    import signal
    import threading
    import time
    from evlife import batch
    events = evlife.read(data("reference/stripes.mat"))
    span = int(events["t"][-1]) + 1000
    copies = 16  # 5.4 M events: about a second of work per task after the signal
    big = np.tile(events, copies)
    big["t"] = np.concatenate([events["t"] + k * span for k in range(copies)])
    paths = []
    for name in ("a.npy", "b.npy"):
        np.save(tmp_path / name, big)
        paths.append(str(tmp_path / name))
    out = tmp_path / "out"
    out.mkdir()
    previous = b"a previous run's output"  # left as it was by a task that did not finish
    for name in ("a.bin", "b.bin"):
        (out / name).write_bytes(previous)
    small = data("reference/garfield.mat")  # queued behind the large ones (largest first)

    def interrupt_once_writing():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            sizes = [f.stat().st_size for f in out.glob(".evlife-partial-*.[ab].bin")]
            if any(size > (1 << 20) for size in sizes):
                os.kill(os.getpid(), signal.SIGINT)
                return
            time.sleep(0.01)

    watcher = threading.Thread(target=interrupt_once_writing)
    watcher.start()
    try:
        with pytest.raises(evlife.Interrupted) as caught:
            batch.process_files([small] + paths, out, workers=2, progress=False)
    finally:
        watcher.join()
    e = caught.value
    assert "recordings finished" in str(e)
    rows = e.partial
    assert [r.path for r in rows] == [small] + paths
    unfinished = [r for r in rows if r.error is not None]
    assert unfinished, rows  # the large ones were being written
    for r in unfinished:
        final = out / (os.path.splitext(os.path.basename(r.path))[0] + ".bin")
        if "its task ended meanwhile" in r.error:  # in its worker's last seconds: a whole output
            written, _ = evlife.read_augmented(str(final))
            assert r.output == str(final) and len(written) > 0
            continue
        assert "interrupted before it finished; nothing written" in r.error
        assert r.output is None and r.events is None
        assert math.isnan(r.seconds)  # not known (it said 0.0)
        if final.name in ("a.bin", "b.bin"):
            assert final.read_bytes() == previous, (rows, os.listdir(out))
        else:
            assert not final.exists()
    assert not list(out.glob(".evlife-partial.*"))  # the stopped tasks' partial files removed
    for r in rows:
        if r.error is None:  # finished: the whole file
            written, _ = evlife.read_augmented(r.output)
            assert len(written) == r.events > 0
    assert e.events_processed == sum(r.events for r in rows if r.error is None)


def test_partial_names_take_no_recordings_or_outputs_name(tmp_path, capsys):
    # A recording named as another's partial output, and a folder of an
    # output's name: each task writes its own file (the partial name holds the
    # call's random id), and a failed rename leaves no partial file behind.
    from evlife import batch
    src = data("reference/garfield.mat")
    out = tmp_path / "out"
    out.mkdir()
    shutil.copy(src, out / ".evlife-partial.a.mat")  # an input inside out_dir
    a = tmp_path / "a.mat"
    shutil.copy(src, a)
    (out / "c.bin").mkdir()  # a folder where an output goes
    c = tmp_path / "c.mat"
    shutil.copy(src, c)
    table = batch.process_files([str(out / ".evlife-partial.a.mat"), str(a), str(c)], out, workers=1)
    assert table[0].error is None and table[1].error is None, table
    # A failure that counted no event: its progress line has its seconds only (it said "None events").
    assert re.search(r"^evlife.batch: \d/3 %s \(\d+\.\d\d s\) FAILED: cannot write " % re.escape(str(c)),
                     capsys.readouterr().err, re.M)
    assert table[0].output != table[1].output
    first, _ = evlife.read_augmented(table[0].output)
    second, _ = evlife.read_augmented(table[1].output)
    assert len(first) == len(second) > 0
    assert (out / ".evlife-partial.a.mat").read_bytes() == open(src, "rb").read()  # the input kept
    assert table[2].error is not None and "cannot write" in table[2].error and table[2].output is None
    assert not [n for n in os.listdir(out) if n.startswith(".evlife-partial-")]


def test_a_worker_that_dies_mid_write_leaves_no_cut_partial_file(tmp_path, capsys):
    # A worker killed while writing (out of memory, a node lost): Dask gives
    # up with KilledWorker. Its cut .evlife-partial-RUN.NAME stayed in out_dir
    # (a .bin cut short reads as a shorter recording) and the row said nothing of it.
    import dask
    from distributed import Client, LocalCluster
    from evlife import batch

    def die_mid_write(path, output, *args, **kwargs):  # the worker dies with the partial output half written
        with open(output, "wb") as f:
            f.write(b"\0" * 4096)
        os._exit(1)

    def install():
        from evlife import _evlife
        _evlife.process_file = die_mid_write  # this worker process only: its replacement runs the real one

    out = tmp_path / "out"
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, \
                Client(cluster) as client:
            client.run(install)
            table = batch.process_files([data("reference/garfield.mat")], out, client)
            client.wait_for_workers(1)  # the nanny's new worker: not closed while it starts
    row = table[0]
    # Its progress line said "(None events, 0.00 s)": neither figure was known.
    progress = [line for line in capsys.readouterr().err.splitlines() if line.startswith("evlife.batch: 1/1 ")]
    assert progress == ["evlife.batch: 1/1 %s (failed: worker killed) FAILED: %s" % (
        data("reference/garfield.mat"), row.error.splitlines()[0])], progress
    assert row.error is not None and "KilledWorker" in row.error, row
    assert row.output is None and row.events is None
    # Nor its time: NaN, a blank in the table (they said 0.0 and 0.00).
    assert math.isnan(row.seconds)
    assert re.search(r"garfield\.mat +FAILED: ", str(table)), str(table)
    assert "partial output" in row.error and "removed" in row.error, row.error
    assert not [n for n in os.listdir(out) if n.startswith(".evlife-partial-")], os.listdir(out)


def test_rejected_events_and_skipped_records_of_a_task_are_warned_of(tmp_path):
    # evlife.process warns of events the estimator rejected (labelled noise)
    # and the CLI prints them; process_files' row said "ok" and nothing more.
    import warnings
    from evlife import batch
    events = evlife.read(data("reference/stripes.mat"))
    events["t"][-3:] = 2**62 + np.arange(3)  # beyond +-2^62 us: rejected by the estimator
    np.save(tmp_path / "late.npy", events)
    aedat4 = data(RECORDINGS["aedat4"])  # frames/IMU records: skipped, as the CLI's summary counts them
    with warnings.catch_warnings(record=True) as warned:
        warnings.simplefilter("always", RuntimeWarning)
        table = batch.process_files([str(tmp_path / "late.npy"), aedat4], tmp_path / "out", workers=1,
                                    progress=False, sensor=(240, 180))
    assert not table.failed, table
    ours = [w for w in warned if issubclass(w.category, RuntimeWarning) and "evlife.batch" in str(w.message)]
    texts = [str(w.message) for w in ours]
    assert any("late.npy" in t and "rejected" in t and "time beyond" in t for t in texts), texts
    assert any("sample.aedat4" in t and "non-event records" in t for t in texts), texts
    assert all(w.filename == __file__ for w in ours), [w.filename for w in ours]


def test_process_slices_warns_of_rejected_events_and_skipped_records_as_evlife_process(tmp_path):
    # process_slices said nothing of them, where evlife.process and process_files warn. Every
    # warm-up here re-reads the first slice's rejected events: counted once, by the slice they are in.
    import warnings
    from evlife import batch
    events = evlife.read(data("reference/stripes.mat"))
    events["t"][:3] = -2**62 - 10 + np.arange(3)  # beyond +-2^62 us: rejected by the estimator,
    events["t"][-3:] = 2**62 + 1 + np.arange(3)  # the first slice's and the last's
    np.save(tmp_path / "far.npy", events)
    aedat4 = os.path.abspath(data(RECORDINGS["aedat4"]))  # frames/IMU records: skipped, counted by one scan
    for path in (str(tmp_path / "far.npy"), aedat4):  # absolute: process_slices names the path so
        with warnings.catch_warnings(record=True) as expected:
            warnings.simplefilter("always")
            evlife.process(path)
        expected = [str(w.message).replace("evlife.process:", "evlife.batch.process_slices:", 1)
                    for w in expected if issubclass(w.category, RuntimeWarning)]
        assert expected and all("rejected" in t or "non-event records" in t for t in expected), expected
        if path.endswith("far.npy"):
            assert expected == ["evlife.batch.process_slices: %s: events rejected (labelled noise, lifetime 0): "
                                "0 outside the sensor, 0 bad polarity, 6 time beyond +-2^62 us" % path]
        with warnings.catch_warnings(record=True) as warned:
            warnings.simplefilter("always")
            batch.process_slices(path, tmp_path / "sl.bin", slices=3, warmup_ms=1e19, workers=1, progress=False)
        ours = [w for w in warned if issubclass(w.category, RuntimeWarning) and "evlife.batch" in str(w.message)]
        assert [str(w.message) for w in ours] == expected
        assert all(w.filename == __file__ for w in ours), [w.filename for w in ours]


def test_ctrl_c_in_process_slices_on_your_cluster_leaves_no_part_file(tmp_path, monkeypatch):
    # Ctrl-C while process_slices waited on a cluster of the user's: its
    # queued slices were not cancelled and ran on, each writing its
    # OUTPUT.partK.bin after the call had removed the parts and raised.
    import time
    import distributed
    from distributed import Client, LocalCluster
    from evlife import batch
    events = evlife.read(data("reference/stripes.mat"))
    span = int(events["t"][-1]) + 1000
    big = np.tile(events, 4)
    big["t"] = np.concatenate([events["t"] + k * span for k in range(4)])
    np.save(tmp_path / "big.npy", big)
    output = tmp_path / "sl.bin"
    first_part = tmp_path / "sl.bin.part0.bin"
    result = distributed.Future.result

    def interrupted_once_slice_0_writes(self, *args, **kwargs):  # Ctrl-C while waiting, as the user presses it
        monkeypatch.setattr(distributed.Future, "result", result)
        deadline = time.monotonic() + 60
        while not first_part.exists() and time.monotonic() < deadline:
            time.sleep(0.005)
        raise KeyboardInterrupt

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        monkeypatch.setattr(distributed.Future, "result", interrupted_once_slice_0_writes)
        # Kept, as an interactive session keeps the last exception (sys.last_value) and its frames.
        with pytest.raises(KeyboardInterrupt) as caught:
            batch.process_slices(big_path := str(tmp_path / "big.npy"), output, slices=6, scheduler=client,
                                 sensor=(240, 180), progress=False)
        # The worker's one thread: this runs after every slice it still runs (submitted before it).
        assert client.submit(os.path.exists, big_path, pure=False).result()
        assert caught.value is not None
    assert not [n for n in os.listdir(tmp_path) if ".part" in n], os.listdir(tmp_path)
    assert not output.exists()


def test_a_slice_that_starts_as_process_slices_gives_up_leaves_no_part_file(tmp_path, monkeypatch):
    # Dask cannot stop a running task, and a queued slice can start before the
    # cancel reaches its worker: such a slice created its part file after the
    # call had removed the parts and raised, and the file stayed. Here slice 0
    # creates its part only once the call has raised, as a slice starting then.
    import threading
    import distributed
    from distributed import Client, LocalCluster
    from evlife import _evlife, batch
    slider = data("rpg_txt/slider_depth_events_chunk.txt")
    started, raised = threading.Event(), threading.Event()
    real_process_time_range = _evlife._process_time_range

    def late_process_time_range(path, part, *args, **kwargs):
        started.set()
        assert raised.wait(60)
        return real_process_time_range(path, part, *args, **kwargs)

    result = distributed.Future.result

    def interrupted_once_slice_0_runs(self, *args, **kwargs):  # Ctrl-C while waiting
        monkeypatch.setattr(distributed.Future, "result", result)
        assert started.wait(60)
        raise KeyboardInterrupt

    monkeypatch.setattr(_evlife, "_process_time_range", late_process_time_range)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        monkeypatch.setattr(distributed.Future, "result", interrupted_once_slice_0_runs)
        with pytest.raises(KeyboardInterrupt):
            batch.process_slices(slider, tmp_path / "sl.bin", slices=3, scheduler=client, progress=False)
        assert not [n for n in os.listdir(tmp_path) if ".part" in n], os.listdir(tmp_path)
        raised.set()
        # The worker's one thread: this runs once slice 0 has ended (the others never start).
        assert client.submit(os.path.exists, slider, pure=False).result()
        written = [n for n in os.listdir(tmp_path) if ".part" in n]
    assert not written, written
    assert not (tmp_path / "sl.bin").exists()


def test_a_task_that_ends_after_ctrl_c_on_your_cluster_writes_nothing(tmp_path, monkeypatch):
    # On a cluster of yours Dask cannot stop a running task: it renamed its
    # output into out_dir after the call had raised (its row said it "may still
    # run on your cluster and write" it), and a queued task could start before
    # the cancel reached its worker. Here the running task ends once the call
    # has raised, and the cancel never arrives (the queued task must not start).
    import threading
    import distributed
    from distributed import Client, LocalCluster
    from evlife import _evlife, batch
    recordings = [data("reference/garfield.mat"), data("reference/stripes.mat")]
    started, raised = threading.Event(), threading.Event()
    real_process_file = _evlife.process_file
    calls = []

    def held_process_file(*args, **kwargs):
        calls.append(args[0])
        started.set()
        assert raised.wait(60)
        return real_process_file(*args, **kwargs)

    def interrupted_once_a_task_runs(futures, *args, **kwargs):  # Ctrl-C while waiting
        assert started.wait(60)
        raise KeyboardInterrupt
        yield  # never reached: a generator, as as_completed is iterated

    monkeypatch.setattr(_evlife, "process_file", held_process_file)
    monkeypatch.setattr(distributed.Client, "cancel", lambda *args, **kwargs: None)
    monkeypatch.setattr(distributed, "as_completed", interrupted_once_a_task_runs)
    out = tmp_path / "out"
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        with pytest.raises(evlife.Interrupted) as caught:
            batch.process_files(recordings, out, client, progress=False)
        rows = caught.value.partial
        assert [r.error for r in rows] == ["interrupted before it finished; nothing written (a task still running "
                                           "on your cluster removes its partial output when it ends)"] * 2, rows
        raised.set()
        # The worker's one thread: this runs once both tasks have ended.
        assert client.submit(os.path.exists, recordings[0], pure=False).result()
        written = os.listdir(out)
    assert written == [], written
    assert len(calls) == 1, calls  # the queued task saw the call give up before it read its recording


def test_a_task_renaming_its_output_as_the_call_gives_up_waits_for_the_lock_and_writes_nothing(tmp_path):
    # The last window of the protocol above: the task checked the Event (not
    # set) and is about to rename while the call sets it; the call then no
    # longer looks for outputs. The check and the rename hold the call's Lock,
    # as the setting does. Here the test is the call: it holds the Lock, the
    # task comes to its rename, the Event is set, the Lock released. Whenever
    # the task reached the rename, it must not write (without the Lock it
    # renamed within the second it is given here).
    import threading
    import time
    from distributed import Client, Event, LocalCluster, Lock
    from evlife import batch
    stop = "evlife-batch-stop-test"
    partial, output = tmp_path / ".evlife-partial-test.x.bin", tmp_path / "x.bin"
    partial.write_bytes(b"whole")
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        lock = Lock(stop, client=client)
        assert lock.acquire(timeout=10)
        replaced = []
        task = threading.Thread(target=lambda: replaced.append(batch._replace_unless_stopped(partial, output, stop)))
        task.start()
        time.sleep(1)  # the task comes to its rename (the Lock)
        Event(stop, client=client).set()
        lock.release()
        task.join(60)
        assert replaced == [False]
    assert os.listdir(tmp_path) == []


def test_ctrl_c_in_a_terminal_reaching_the_workers_too_leaves_no_output_written_later(tmp_path):
    # Ctrl-C in a terminal is a SIGINT to the whole foreground process group:
    # the workers of a LocalCluster that the script started get it too. Their
    # connection to the scheduler ends, but a task's thread runs on, and it
    # renamed its output into out_dir after the call had raised and said it
    # would not (the Event could not be read: taken as not given up on). Here
    # the script holds its workers' tasks until the test lets them go, after
    # the Ctrl-C.
    import json
    import signal
    import subprocess
    import sys
    import time
    started, go, out = tmp_path / "started", tmp_path / "go", tmp_path / "out"
    script = tmp_path / "interrupted.py"
    script.write_text(
        "import json, os, time, evlife\n"
        "from evlife import batch\n"
        "from distributed import Client, LocalCluster\n"
        "def hold_tasks():  # in each worker: a task waits for the test before it reads its recording\n"
        "    from evlife import _evlife\n"
        "    real = _evlife.process_file\n"
        "    def held(*args, **kwargs):\n"
        "        open(%r, 'w').close()\n"
        "        while not os.path.exists(%r):\n"
        "            time.sleep(0.02)\n"
        "        return real(*args, **kwargs)\n"
        "    _evlife.process_file = held\n"
        "if __name__ == '__main__':\n"
        "    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=':0') as c, \\\n"
        "            Client(c) as client:\n"
        "        client.run(hold_tasks)\n"
        "        try:\n"
        "            batch.process_files([%r], %r, client, progress=False)\n"
        "        except evlife.Interrupted as e:\n"
        "            print(json.dumps([r.error for r in e.partial]), flush=True)\n"
        "        time.sleep(120)  # the cluster stays: the test ends this script\n"
        % (str(started), str(go), data("reference/garfield.mat"), str(out)))
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(evlife.__file__)))
    run = subprocess.Popen([sys.executable, str(script)], env=env, cwd=tmp_path, start_new_session=True,
                           stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        deadline = time.monotonic() + 120
        while not started.exists():  # the task runs
            assert run.poll() is None and time.monotonic() < deadline, "the task never started"
            time.sleep(0.05)
        os.killpg(run.pid, signal.SIGINT)  # Ctrl-C: the script and its workers
        rows = json.loads(run.stdout.readline())
        assert rows == ["interrupted before it finished; nothing written (a task still running on your "
                        "cluster removes its partial output when it ends)"], rows
        go.touch()  # the task reads on and ends within a second (it wrote out/garfield.bin then)
        time.sleep(5)
        assert sorted(os.listdir(out)) == [], os.listdir(out)
    finally:
        os.killpg(run.pid, signal.SIGKILL)
        run.wait()


def _held(monkeypatch, module, name):
    """module.name patched to wait, once called, until `release` is set
    (`started` set when called): a task that runs while the test acts."""
    import threading
    started, release = threading.Event(), threading.Event()
    real = getattr(module, name)

    def held(*args, **kwargs):
        started.set()
        assert release.wait(60)
        return real(*args, **kwargs)

    monkeypatch.setattr(module, name, held)
    return started, release


@contextlib.contextmanager
def _cluster_losing_its_scheduler(started, release):
    """A thread-worker LocalCluster and its Client, whose scheduler is closed
    once `started` is set; yields (client, the scheduler's address). At the
    end `release` is set and both are closed without waiting out Dask's
    timeouts for the scheduler that is gone (30 s)."""
    import threading
    from distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0")
    cluster.shutdown_on_close = False  # (SpecCluster's) else Dask's exit handler closes it again: 10 s more
    client = Client(cluster)
    try:
        threading.Thread(target=lambda: started.wait(60) and cluster.sync(cluster.scheduler.close)).start()
        yield client, cluster.scheduler.address
    finally:
        release.set()
        with contextlib.suppress(TimeoutError):
            cluster.close(timeout=2)
        with contextlib.suppress(TimeoutError):
            client.close(timeout=2)


def _wait_for(condition):
    """Polls `condition` for up to 20 s. A task whose worker lost its
    scheduler ends at once (0.2 s here): it held its worker 30 s (Dask's
    connect timeout) waiting for the call's Lock from a client reconnecting
    to no scheduler."""
    import time
    deadline = time.monotonic() + 20
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.05)


def test_a_scheduler_that_goes_away_is_named_in_the_rows_and_the_running_task_writes_nothing(tmp_path, monkeypatch):
    # A cluster's scheduler crashes (or the network to it is cut) while a
    # recording's task runs: Dask cancels every task, and the rows said only
    # "CancelledError: evlife-3f2a9c1e-0-garfield.mat". The task's thread runs
    # on in its worker; it must not rename its output into out_dir afterwards.
    from evlife import _evlife, batch
    started, release = _held(monkeypatch, _evlife, "process_file")
    renamed, real_replace = [], batch._replace_unless_stopped

    def recorded_replace(*args):
        renamed.append(real_replace(*args))
        return renamed[-1]

    monkeypatch.setattr(batch, "_replace_unless_stopped", recorded_replace)
    out = tmp_path / "out"
    with _cluster_losing_its_scheduler(started, release) as (client, address):
        table = batch.process_files([data("reference/garfield.mat")], out, client, progress=False)
        release.set()
        _wait_for(lambda: renamed)
        ended_in_time = list(renamed)  # (the close ends a wait too)
    assert [r.error for r in table] == ["lost the connection to the scheduler %s (CancelledError) (nothing written; "
                                        "its partial output, if any, was removed)" % address], table
    assert ended_in_time == [False]
    assert os.listdir(out) == []


def test_a_scheduler_that_goes_away_is_named_by_process_slices_and_the_running_slice_leaves_no_part(tmp_path,
                                                                                                   monkeypatch):
    # As above, for slices: the call raised CancelledError naming a task key.
    from evlife import _evlife, batch
    started, release = _held(monkeypatch, _evlife, "_process_time_range")
    checks, real_stopped = [], batch._stopped

    def recorded_stopped(*args):  # the slice's checks: at its start, once its part is whole
        checks.append(real_stopped(*args))
        return checks[-1]

    monkeypatch.setattr(batch, "_stopped", recorded_stopped)
    out = tmp_path / "out"
    out.mkdir()
    recording = data("reference/garfield.mat")
    with _cluster_losing_its_scheduler(started, release) as (client, address):
        with pytest.raises(RuntimeError) as caught:
            batch.process_slices(recording, out / "g.bin", 2, scheduler=client, progress=False)
        release.set()
        _wait_for(lambda: len(checks) >= 2 and not os.listdir(out))
        checked_in_time = list(checks)
    assert str(caught.value) == ("evlife.batch.process_slices: %s: slice 0: lost the connection to the scheduler %s "
                                 "(CancelledError)" % (os.path.abspath(recording), address))
    assert checked_in_time == [False, True]  # it saw no call to deliver to: it removed its part
    assert os.listdir(out) == []


def test_a_task_that_could_not_ask_the_scheduler_says_so_where_the_call_still_waits(tmp_path, monkeypatch):
    # A worker that cannot read the call's Event counts as given up on and
    # writes nothing (_stopped); where its result reaches the call anyway
    # (the connection came back), the row must not say "interrupted".
    from distributed import Client, LocalCluster
    from evlife import batch
    monkeypatch.setattr(batch, "_stopped", lambda *args: True)
    out = tmp_path / "out"
    recording = data("reference/garfield.mat")
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        table = batch.process_files([recording], out, client, progress=False)
        with pytest.raises(RuntimeError) as caught:
            batch.process_slices(recording, out / "g.bin", 2, scheduler=client, progress=False)
    assert [r.error for r in table] == ["its worker could not reach the scheduler; nothing written"], table
    assert str(caught.value) == ("evlife.batch.process_slices: %s: slice 0 wrote nothing: its worker could not "
                                 "reach the scheduler" % os.path.abspath(recording))
    assert os.listdir(out) == []


def _interrupted_submit(monkeypatch, started, key_part):
    """Client.submit patched to raise KeyboardInterrupt (Ctrl-C) for the task
    whose key holds `key_part`, once `started`; Dask's cancel never arrives
    (as where a task already runs). Returns the real submit."""
    import distributed
    real_submit = distributed.Client.submit

    def submit(self, *args, **kwargs):
        if key_part in kwargs["key"]:
            assert started.wait(60)
            raise KeyboardInterrupt
        return real_submit(self, *args, **kwargs)

    monkeypatch.setattr(distributed.Client, "submit", submit)
    monkeypatch.setattr(distributed.Client, "cancel", lambda *args, **kwargs: None)
    return real_submit


def _interrupted_while_submitting(call, recording, release, real_submit, out):
    """Runs call(client) on a thread-worker cluster; returns what it raised
    and out's files once the held task ended (the worker's one thread runs a
    later task after it)."""
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        try:
            with pytest.raises(BaseException) as caught:  # (a bare KeyboardInterrupt would end pytest)
                call(client)
        finally:
            release.set()
        assert real_submit(client, os.path.exists, recording, pure=False).result()
        return caught.value, os.listdir(out)


def test_ctrl_c_while_the_tasks_are_submitted_gives_up_on_those_submitted(tmp_path, monkeypatch):
    # Submitting thousands of recordings takes seconds: a Ctrl-C then raised
    # a bare KeyboardInterrupt, and the tasks already submitted ran on (on a
    # cluster of yours) and wrote their outputs after the call had raised.
    # Here the second submit is interrupted while the first task runs.
    from evlife import _evlife, batch
    started, release = _held(monkeypatch, _evlife, "process_file")
    real_submit = _interrupted_submit(monkeypatch, started, "-1-stripes.mat")
    out = tmp_path / "out"
    recordings = [data("reference/garfield.mat"), data("reference/stripes.mat")]
    raised, written = _interrupted_while_submitting(
        lambda client: batch.process_files(recordings, out, client, progress=False),
        recordings[0], release, real_submit, out)
    assert isinstance(raised, evlife.Interrupted), repr(raised)
    assert [r.error for r in raised.partial] == [
        "interrupted before it finished; nothing written (a task still running on your cluster removes its "
        "partial output when it ends)"] * 2
    assert written == [], written


def test_ctrl_c_while_the_slices_are_submitted_leaves_no_part_file(tmp_path, monkeypatch):
    # As above, for slices: the slices submitted before the Ctrl-C ran on and
    # wrote their part files after the call had removed the parts.
    from evlife import _evlife, batch
    started, release = _held(monkeypatch, _evlife, "_process_time_range")
    real_submit = _interrupted_submit(monkeypatch, started, "-1-garfield.mat")
    out = tmp_path / "out"
    out.mkdir()
    recording = data("reference/garfield.mat")
    raised, written = _interrupted_while_submitting(
        lambda client: batch.process_slices(recording, out / "g.bin", 2, scheduler=client, progress=False),
        recording, release, real_submit, out)
    assert type(raised) is KeyboardInterrupt, repr(raised)
    assert written == [], written


def test_a_recording_whose_name_is_not_utf8_is_processed_with_the_others(tmp_path):
    # A file name in Latin-1 (b"caf\xe9.mat", as older systems and cameras write
    # them): its task key held the name's lone surrogate, which Dask's messages
    # (msgpack) cannot encode. The connection broke and every row, the other
    # recordings' too, failed with CancelledError after pages of tracebacks.
    from evlife import batch
    src = data("reference/garfield.mat")
    latin1 = os.path.join(os.fsencode(tmp_path), b"caf\xe9.mat")
    shutil.copy(src, latin1)
    plain = str(tmp_path / "plain.mat")
    shutil.copy(src, plain)
    table = batch.process_files([latin1, plain], tmp_path / "out", workers=1, progress=False)
    assert not table.failed, table
    assert [r.path for r in table] == [os.fsdecode(latin1), plain]
    assert os.fsencode(table[0].output).endswith(b"/caf\xe9.bin")
    assert open(table[0].output, "rb").read() == open(table[1].output, "rb").read()


def test_threaded_workers_keep_each_tasks_warnings_and_leave_the_callers_warnings_as_they_were(tmp_path, monkeypatch):
    # A LocalCluster(processes=False) (a notebook's): the tasks run on threads
    # of the caller's process, and each task's warnings.catch_warnings
    # patched and restored the process's warnings module. Two tasks that
    # overlapped (A enters, B enters, A leaves, B leaves) left A's recorder
    # installed for good: every later warning of the process went into a dead
    # list, unseen, and the "always" filter stayed; B's warning was printed on
    # stderr, not the caller's.
    import threading
    import time
    import warnings
    from distributed import Client, LocalCluster
    from evlife import _evlife, batch
    out = tmp_path / "out"
    both_inside = threading.Barrier(2, timeout=30)

    def fake_process_file(path, output, *args, **kwargs):
        both_inside.wait()  # both tasks inside their warnings capture
        if path.endswith("b.mat"):  # B goes on once A has left its capture (A's output renamed after it)
            deadline = time.monotonic() + 30
            while not (out / "a.bin").exists() and time.monotonic() < deadline:
                time.sleep(0.005)
        warnings.warn("task warning of %s" % path, RuntimeWarning)
        with open(output, "wb") as f:
            f.write(b"x")
        return {"events": 1, "with_lifetime": 1, "rejected": {}, "skipped_records": 0}

    paths = []
    for name in ("a.mat", "b.mat"):
        shutil.copy(data("reference/garfield.mat"), tmp_path / name)
        paths.append(str(tmp_path / name))
    monkeypatch.setattr(_evlife, "process_file", fake_process_file)
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        filters, show = list(warnings.filters), warnings._showwarnmsg_impl
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
                Client(cluster) as client:
            with warnings.catch_warnings(record=True) as warned:
                warnings.simplefilter("always", RuntimeWarning)
                table = batch.process_files(paths, out, client, progress=False)
            after = list(warnings.filters), warnings._showwarnmsg_impl
    assert not table.failed, table
    texts = sorted(str(w.message) for w in warned if "task warning" in str(w.message))
    assert texts == ["task warning of %s" % p for p in paths], texts
    assert after == (filters, show)


def test_a_slice_whose_worker_dies_names_the_recording_and_leaves_no_part_file(tmp_path):
    # KilledWorker said only "Attempted to run task evlife-slice-RUN-0": not which recording.
    import dask
    from distributed import Client, LocalCluster
    from evlife import batch

    def die_mid_write(path, part, *args, **kwargs):
        with open(part, "wb") as f:
            f.write(b"\0" * 4096)
        os._exit(1)

    def install():
        from evlife import _evlife
        _evlife._process_time_range = die_mid_write

    output = tmp_path / "sl.bin"
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, \
                Client(cluster) as client:
            client.run(install)
            with pytest.raises(Exception) as caught:
                batch.process_slices(data("reference/garfield.mat"), output, slices=2, scheduler=client,
                                     progress=False)
            client.wait_for_workers(1)
    assert "garfield.mat" in str(caught.value), caught.value
    assert not [n for n in os.listdir(tmp_path) if ".part" in n] and not output.exists(), os.listdir(tmp_path)


def test_ctrl_c_keeps_the_warnings_of_the_finished_rows(tmp_path, monkeypatch):
    # The warnings of the recordings finished before Ctrl-C (events rejected
    # here) were dropped with the interruption, though their rows are in .partial.
    import warnings
    import distributed
    from evlife import batch
    events = evlife.read(data("reference/stripes.mat"))
    events["t"][-3:] = 2**62 + np.arange(3)
    np.save(tmp_path / "late.npy", events)
    real = distributed.as_completed

    def interrupted_after_the_first(futures, *args, **kwargs):  # Ctrl-C once a row is in
        yield next(iter(real(futures, *args, **kwargs)))
        raise KeyboardInterrupt

    monkeypatch.setattr(distributed, "as_completed", interrupted_after_the_first)
    with warnings.catch_warnings(record=True) as warned:
        warnings.simplefilter("always", RuntimeWarning)
        with pytest.raises(evlife.Interrupted) as caught:
            batch.process_files([str(tmp_path / "late.npy"), data("reference/garfield.mat")], tmp_path / "out",
                                workers=1, progress=False, sensor=(240, 180))
    late = caught.value.partial[0]
    assert late.error is None and late.events > 0, caught.value.partial  # the largest: first
    texts = [str(w.message) for w in warned if "evlife.batch" in str(w.message)]
    assert any("late.npy" in t and "rejected" in t for t in texts), texts
    assert all(w.filename == __file__ for w in warned if "evlife.batch" in str(w.message))


class _LineWatch:
    """sys.stderr for a test: keeps what is written, sets `seen` at the first
    line holding `wanted`."""

    def __init__(self, wanted):
        self.wanted, self.text, self.seen = wanted, "", __import__("threading").Event()

    def write(self, text):
        self.text += text
        if self.wanted in self.text:
            self.seen.set()
        return len(text)

    def flush(self):
        pass


def test_a_batch_waiting_on_a_long_recording_says_it_is_still_running(tmp_path, monkeypatch):
    # A recording that takes an hour left its batch silent for an hour: only finished
    # recordings had a line. Here the task (on a thread of this process) waits for that
    # line before it goes on, so the line comes before the task ends however fast the
    # machine, and names the output being written with its size.
    from distributed import Client, LocalCluster
    from evlife import _evlife, batch
    slider = data("rpg_txt/slider_depth_events_chunk.txt")
    monkeypatch.setattr(batch, "STILL_RUNNING_EVERY_S", 0.3)
    watch = _LineWatch("; writing: slider_depth_events_chunk.bin (1.0 MB)\n")
    real_process_file = _evlife.process_file

    def slow_process_file(path, output, *args, **kwargs):
        with open(output, "wb") as f:
            f.write(b"\0" * 1_000_000)
        watch.seen.wait(60)
        return real_process_file(path, output, *args, **kwargs)

    monkeypatch.setattr(_evlife, "process_file", slow_process_file)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        monkeypatch.setattr("sys.stderr", watch)
        table = batch.process_files([slider], tmp_path / "out", client)
        monkeypatch.undo()
    assert watch.seen.is_set(), watch.text
    assert table[0].error is None and table[0].events > 0, table[0]
    expected = tmp_path / "cli.bin"
    cli("process", slider, "-o", expected, "-q")
    assert open(table[0].output, "rb").read() == expected.read_bytes()
    lines = watch.text.splitlines()
    assert re.fullmatch(r"evlife\.batch: 0/1 done; none finished for \d+ s; writing: "
                        r"slider_depth_events_chunk\.bin \(1\.0 MB\)", lines[0]), lines
    assert lines[-1].startswith("evlife.batch: 1/1 %s (" % slider), lines


def test_slices_waiting_on_a_long_slice_say_they_are_still_running(tmp_path, monkeypatch):
    # As process_files: a slice that takes long gets a line while it runs, naming its part file.
    from distributed import Client, LocalCluster
    from evlife import _evlife, batch
    slider = data("rpg_txt/slider_depth_events_chunk.txt")
    monkeypatch.setattr(batch, "STILL_RUNNING_EVERY_S", 0.3)
    watch = _LineWatch("; writing: sl.bin.part0.bin (1.0 MB)\n")
    real_process_time_range = _evlife._process_time_range

    def slow_process_time_range(path, part, *args, **kwargs):
        with open(part, "wb") as f:
            f.write(b"\0" * 1_000_000)
        watch.seen.wait(60)
        return real_process_time_range(path, part, *args, **kwargs)

    monkeypatch.setattr(_evlife, "_process_time_range", slow_process_time_range)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        monkeypatch.setattr("sys.stderr", watch)
        table = batch.process_slices(slider, tmp_path / "sl.bin", slices=2, scheduler=client)
        monkeypatch.undo()
    assert watch.seen.is_set(), watch.text
    assert len(table) == 2 and all(r.events > 0 for r in table), table
    lines = watch.text.splitlines()
    assert re.fullmatch(r"evlife\.batch: 0/2 slices of %s done; none finished for \d+ s; writing: "
                        r"sl\.bin\.part0\.bin \(1\.0 MB\)(, sl\.bin\.part1\.bin \(\d+\.\d MB\))?"
                        % re.escape(os.path.abspath(slider)), lines[0]), lines
    assert lines[-1].startswith("evlife.batch: slice 2/2 of %s (" % os.path.abspath(slider)), lines


def test_the_still_running_line_names_the_outputs_being_written_with_their_sizes(tmp_path, monkeypatch):
    from evlife import batch
    written = tmp_path / "a.bin"
    written.write_bytes(b"\0" * 2_500_000)
    monkeypatch.setattr(batch, "STILL_RUNNING_EVERY_S", 0.1)
    watch = _LineWatch("\n")
    monkeypatch.setattr("sys.stderr", watch)
    with batch._StillRunning(True, lambda: "2/5 done", lambda: [("a.bin", str(written)),
                                                              ("b.bin", str(tmp_path / "not yet"))]):
        assert watch.seen.wait(60)
    assert watch.text.splitlines()[0] == "evlife.batch: 2/5 done; none finished for 0 s; writing: a.bin (2.5 MB)"
    # progress=False: no thread, no line; a finished line is not printed either.
    quiet = _LineWatch("\n")
    monkeypatch.setattr("sys.stderr", quiet)
    with batch._StillRunning(False, lambda: "0/1 done", lambda: []) as still_running:
        still_running.finished("evlife.batch: 1/1 x (1 events, 0.00 s) ok")
        assert not quiet.seen.wait(0.5)
    assert quiet.text == ""
