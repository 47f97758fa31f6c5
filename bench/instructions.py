#!/usr/bin/env python3
"""Counts the instructions the estimator executes per event (valgrind's callgrind).

On the shared 2-vCPU machines a build's speed moves by up to ±25 % from one
run to the next (bench/alternate.py, an A/A run), so a change worth a few
per cent cannot be timed there. The instructions executed are the same in
every run: this script counts them per event for each bench_estimator build
and benchmark, with the functions that execute most. Fewer instructions is not
always faster (a wait for memory costs none): time the change as well, with
bench/alternate.py, before calling it a gain.

  # this build against another, the default recordings and scene:
  bench/instructions.py build/bench/bench_estimator /tmp/main/bench/bench_estimator
  # N = 7 on stripes, the ten costliest functions:
  bench/instructions.py --filter 'N7_reg/stripes$' --top 10 build/bench/bench_estimator

Needs valgrind (Debian: apt-get install valgrind); each benchmark runs one
iteration under it, ~50x slower than natively (synthetic_1280x720: minutes).
Printed per benchmark: instructions per event of LifetimeEstimator::process()
(inclusive), the ratio to the first binary, and the top functions' own
instructions per event (only those run inside it are counted).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

ESTIMATOR_ENTRY = "evlife::LifetimeEstimator::process(std::span"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("binaries", nargs="+", metavar="BINARY", help="bench_estimator executables; the first is the reference")
    p.add_argument("--filter", default="N5_reg/(stripes|garfield|synthetic_320x180)$",
                   help="--benchmark_filter selecting the benchmarks (a regex; default: %(default)s)")
    p.add_argument("--top", type=int, default=6, help="functions listed per benchmark and binary (default 6)")
    return p.parse_args(argv)


def annotate_counts(text):
    """(count, function) pairs of a callgrind_annotate listing, in its order."""
    rows = []
    for line in text.splitlines():
        m = re.match(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?(\S.*)$", line)
        if m and not m.group(2).startswith("PROGRAM TOTALS"):
            rows.append((int(m.group(1).replace(",", "")), m.group(2)))
    return rows


def function_name(location):
    """'file:function(params) [clone .x] [object]' of callgrind_annotate -> 'function [clone .x]',
    without evlife's namespaces."""
    location = re.sub(r"\s+\[/[^\]]*\]$", "", location)  # the object file
    location = re.sub(r"^[^:]*:(?!:)", "", location)  # the source file (none has a colon)
    clone = re.search(r"\s\[clone [^\]]*\]$", location)
    name = re.sub(r"evlife::|detail::|\(anonymous namespace\)::", "", location).split("(", 1)[0]
    return name + (clone.group(0) if clone else "")


def entry_instructions(inclusive_rows):
    """The estimator's inclusive count: its entry point's row."""
    for count, location in inclusive_rows:
        if ESTIMATOR_ENTRY in location:
            return count
    raise ValueError(f"no {ESTIMATOR_ENTRY}...) in the profile: not a bench_estimator build?")


def run_one(binary, name, workdir):
    profile = os.path.join(workdir, "callgrind.out")
    result = os.path.join(workdir, "result.json")
    # Only what runs inside the estimator's entry point is counted (the
    # recording's decoding or the scene's generation are not).
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={profile}",
           f"--toggle-collect={ESTIMATOR_ENTRY}*", binary,
           f"--benchmark_filter=^{re.escape(name)}$", "--benchmark_min_time=0.01",
           f"--benchmark_out={result}", "--benchmark_out_format=json"]
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{binary} {name}: exit {done.returncode}\n{done.stderr[-2000:]}")
    with open(result) as f:
        bench = json.load(f)["benchmarks"][0]
    if "events" not in bench:
        raise ValueError(f"{binary} {name}: no 'events' counter: not a bench_estimator build?")
    events = bench["iterations"] * bench["events"]
    inclusive = annotate_counts(subprocess.run(["callgrind_annotate", "--inclusive=yes", profile],
                                               capture_output=True, text=True, check=True).stdout)
    own = annotate_counts(subprocess.run(["callgrind_annotate", "--inclusive=no", profile],
                                         capture_output=True, text=True, check=True).stdout)
    own = [(c / events, function_name(loc)) for c, loc in own]
    return entry_instructions(inclusive) / events, own


def benchmark_names(binary, pattern):
    out = subprocess.run([binary, "--benchmark_list_tests", f"--benchmark_filter={pattern}"],
                         capture_output=True, text=True, check=True).stdout.split()
    if not out:
        raise ValueError(f"{binary}: no benchmark matches --filter {pattern!r}")
    return out


def main(argv):
    args = parse_args(argv)
    for binary in args.binaries:
        if not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
            sys.exit(f"instructions.py: {binary}: not an executable file (a bench_estimator build)")
    try:
        names = benchmark_names(args.binaries[0], args.filter)
    except (ValueError, subprocess.CalledProcessError) as e:
        sys.exit(f"instructions.py: {e}")
    for tool in ("valgrind", "callgrind_annotate"):
        if shutil.which(tool) is None:
            sys.exit(f"instructions.py: {tool} not found (Debian: apt-get install valgrind)")
    try:
        report(args, names)
    except (ValueError, RuntimeError, OSError, subprocess.CalledProcessError) as e:
        sys.exit(f"instructions.py: {e}")
    return 0


def report(args, names):
    """Prints each benchmark's instructions per event for every binary."""
    with tempfile.TemporaryDirectory() as workdir:
        for name in names:
            print(name)
            reference = None
            for binary in args.binaries:
                per_event, own = run_one(binary, name, workdir)
                ratio = "" if reference is None else f"; ratio to the first {per_event / reference:.3f}"
                reference = reference or per_event
                print(f"  {binary}: {per_event:,.0f} instructions/event{ratio}")
                for count, function in own[:args.top]:
                    print(f"    {count:8,.1f}  {function[:110]}")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
