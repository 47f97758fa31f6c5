"""bench/alternate.py against a stand-in for a Google Benchmark binary."""
import json
import os
import stat
import subprocess
import sys
import textwrap

SCRIPT = os.path.join(os.path.dirname(__file__), os.pardir, "alternate.py")

# Writes --benchmark_out like Google Benchmark (runs and aggregates), its
# counter values from FAKE_VALUES_<label>, appends "label stdout-is-devnull
# stderr-is-a-pipe" to FAKE_LOG, and exits with FAKE_STATUS.
FAKE = textwrap.dedent("""\
    #!{python}
    import json, os, stat, sys
    label = {label!r}
    args = dict(a[2:].split("=", 1) for a in sys.argv[1:] if a.startswith("--") and "=" in a)
    reps = int(args["benchmark_repetitions"])
    with open(os.environ["FAKE_LOG"], "a") as log:
        log.write(label + " " + str(os.path.samefile("/proc/self/fd/1", os.devnull))
                  + " " + str(stat.S_ISFIFO(os.fstat(2).st_mode)) + "\\n")
    values = json.loads(os.environ["FAKE_VALUES_" + label])
    bench = []
    for name, per_rep in values.items():
        for r in range(reps):
            bench.append({{"name": name, "run_name": name, "run_type": "iteration",
                          "items_per_second": per_rep[r % len(per_rep)], "p99_us": per_rep[r % len(per_rep)]}})
        bench.append({{"name": name + "_median", "run_name": name, "run_type": "aggregate",
                      "items_per_second": -1.0, "p99_us": -1.0}})
    with open(args["benchmark_out"], "w") as f:
        json.dump({{"context": {{}}, "benchmarks": bench}}, f)
    print("console output that must not reach a pipe")
    sys.exit(int(os.environ.get("FAKE_STATUS", "0")))
    """)


def make_fake(tmp_path, label):
    path = tmp_path / f"bench_{label}"
    path.write_text(FAKE.format(python=sys.executable, label=label))
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return str(path)


def run(tmp_path, args, values, status=0):
    env = dict(os.environ, FAKE_LOG=str(tmp_path / "log"), FAKE_STATUS=str(status))
    for label, v in values.items():
        env["FAKE_VALUES_" + label] = json.dumps(v)
    return subprocess.run([sys.executable, SCRIPT] + args, capture_output=True, text=True, env=env, check=False)


def test_alternates_the_binaries_and_compares_medians_by_round(tmp_path):
    a, b = make_fake(tmp_path, "a"), make_fake(tmp_path, "b")
    done = run(tmp_path, ["--rounds", "3", "--repetitions", "3", a, b],
               {"a": {"BM_x": [100.0, 110.0, 300.0]}, "b": {"BM_x": [220.0, 200.0, 100.0]}})
    assert done.returncode == 0, done.stderr
    # A B A B A B, each with its console output on /dev/null and no pipe on stderr.
    assert (tmp_path / "log").read_text().split("\n")[:-1] == ["a True False", "b True False"] * 3
    out = done.stdout
    assert "BM_x" in out
    # Medians of the repetitions (the aggregates' -1 ignored): a 110, b 200.
    assert f"{a}: items_per_second median 110.0 over 9 runs; rounds 110.0 110.0 110.0" in out
    assert f"{b}: items_per_second median 200.0 over 9 runs; rounds 200.0 200.0 200.0; ratio to the first by round 1.818 1.818 1.818" in out
    assert "console output" not in out


def test_counts_the_runs_below_a_value(tmp_path):
    a = make_fake(tmp_path, "a")
    done = run(tmp_path, ["--counter", "p99_us", "--below", "100", "--rounds", "2", "--repetitions", "4", a],
               {"a": {"BM_lat": [50.0, 90.0, 120.0, 1500.0]}})
    assert done.returncode == 0, done.stderr
    assert "p99_us median 105.0 over 8 runs" in done.stdout
    assert "below 100.0 in 4 of 8" in done.stdout


def test_a_failing_binary_is_an_error_that_names_it(tmp_path):
    a = make_fake(tmp_path, "a")
    done = run(tmp_path, [a], {"a": {"BM_x": [1.0]}}, status=3)
    assert done.returncode == 1
    assert a in done.stderr and "status 3" in done.stderr


def test_an_unknown_counter_names_the_benchmark(tmp_path):
    a = make_fake(tmp_path, "a")
    done = run(tmp_path, ["--counter", "nope", a], {"a": {"BM_x": [1.0]}})
    assert done.returncode == 1
    assert "BM_x has no counter 'nope'" in done.stderr


def test_a_missing_binary_is_a_usage_error(tmp_path):
    done = run(tmp_path, [str(tmp_path / "absent")], {})
    assert done.returncode == 2
    assert "absent: not an executable file" in done.stderr


def test_a_binary_that_writes_no_results_is_an_error_not_the_previous_ones(tmp_path):
    # One JSON path serves every run: a binary that exits 0 without writing it
    # was credited with the run before it (ratio 1.000, exit 0).
    a = make_fake(tmp_path, "a")
    silent = tmp_path / "silent"
    silent.write_text("#!/bin/sh\nexit 0\n")
    silent.chmod(silent.stat().st_mode | stat.S_IXUSR)
    done = run(tmp_path, ["--rounds", "1", "--repetitions", "1", a, str(silent)], {"a": {"BM_x": [1.0]}})
    assert done.returncode == 1, done.stdout
    assert f"{silent} wrote no results" in done.stderr


def test_a_filter_that_matches_nothing_says_so(tmp_path):
    # Google Benchmark leaves an empty --benchmark_out then (a JSON error before).
    empty = tmp_path / "empty"
    empty.write_text("#!/bin/sh\nfor a; do case $a in --benchmark_out=*) : > \"${a#--benchmark_out=}\";; esac; done\n")
    empty.chmod(empty.stat().st_mode | stat.S_IXUSR)
    done = run(tmp_path, ["--filter", "NOPE", str(empty)], {})
    assert done.returncode == 1
    assert "no benchmark matches --filter 'NOPE'" in done.stderr


def test_a_binary_given_twice_is_an_a_a_run_with_ratios(tmp_path):
    a = make_fake(tmp_path, "a")
    done = run(tmp_path, ["--rounds", "2", "--repetitions", "2", a, a], {"a": {"BM_x": [100.0, 110.0]}})
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "log").read_text().split("\n")[:-1] == ["a True False"] * 4
    lines = done.stdout.splitlines()
    runs = [line for line in lines if line.startswith(f"  {a}:")]
    assert len(runs) == 2, done.stdout  # one line per place on the command line
    assert all("over 4 runs; rounds 105.0 105.0" in line for line in runs), done.stdout
    assert "ratio" not in runs[0] and "ratio to the first by round 1.000 1.000" in runs[1], done.stdout
