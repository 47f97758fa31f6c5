#!/usr/bin/env python3
"""Runs Google Benchmark binaries in alternation and compares them.

Round after round, each binary runs once (A B A B ...), so that every build
sees the same machine load; the figures are then medians and per-round
ratios, measured in one run. Each run writes its results to a JSON file,
its console output to /dev/null and its stderr to a file: no pipe reader
competes with the benchmark for the CPUs (on 2 vCPUs a `| grep` that wakes
during a latency run shows).

  # estimator throughput, this build against another, three rounds:
  bench/alternate.py --filter N5_reg --repetitions 5 --rounds 3 \\
      build/bench/bench_estimator /tmp/main/bench/bench_estimator
  # engine latency, one build, six batches of four runs, runs under 100 us:
  bench/alternate.py --filter 'BM_EngineLatencySpin/.*kev_per_s:1000/' \\
      --counter p99_us --below 100 --repetitions 4 --rounds 6 build/bench/bench_engine

Printed per benchmark and binary: the median over every run, the medians of
each round, with --below how many runs were below the value, and for the
binaries after the first their per-round ratio to the first (a ratio above 1
means more of the counter: faster for items_per_second, slower for p99_us).
Give a binary twice (an A/A run) to see how far the machine alone moves the
ratios: on the shared 2-vCPU machine here, 0.79-1.20 in two rounds of three.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("binaries", nargs="+", metavar="BINARY", help="Google Benchmark executables; the first is the reference")
    p.add_argument("--filter", default="", help="--benchmark_filter of every run (a regex)")
    p.add_argument("--counter", default="items_per_second",
                   help="the value compared: items_per_second (default), real_time, cpu_time or a user counter such as p99_us")
    p.add_argument("--rounds", type=int, default=3, help="rounds of one run per binary (default 3)")
    p.add_argument("--repetitions", type=int, default=3, help="--benchmark_repetitions of each run (default 3)")
    p.add_argument("--below", type=float, help="also count the runs whose counter is below this value")
    p.add_argument("--arg", action="append", default=[], help="one more argument for every run (repeatable)")
    args = p.parse_args(argv)
    if args.rounds < 1 or args.repetitions < 1:
        p.error("--rounds and --repetitions must be at least 1")
    for b in args.binaries:
        if not (os.path.isfile(b) and os.access(b, os.X_OK)):
            p.error(f"{b}: not an executable file")
    return args


def run_once(binary, args, out_path):
    """One run of `binary`; returns {benchmark name: [counter of each repetition]}."""
    cmd = [binary, f"--benchmark_filter={args.filter}", f"--benchmark_repetitions={args.repetitions}",
           f"--benchmark_out={out_path}", "--benchmark_out_format=json"] + args.arg
    # stderr to a file too (the engine's bench logs there): read only after the run.
    err_path = out_path + ".stderr"
    if os.path.exists(out_path):
        os.remove(out_path)  # never the previous run's results for this one's
    with open(os.devnull, "wb") as null, open(err_path, "wb") as err:
        done = subprocess.run(cmd, stdout=null, stderr=err, check=False)
    if done.returncode != 0:
        with open(err_path, "rb") as err:
            tail = err.read()[-500:].decode(errors="replace")
        raise RuntimeError(f"{binary} exited with status {done.returncode}: {tail}")
    if not os.path.exists(out_path):
        raise RuntimeError(f"{binary} wrote no results to --benchmark_out: not a Google Benchmark binary?")
    if os.path.getsize(out_path) == 0:  # Google Benchmark's output when the filter matches nothing
        raise RuntimeError(f"{binary}: no benchmark matches --filter '{args.filter}'")
    with open(out_path, encoding="utf-8") as f:
        try:
            report = json.load(f)
        except json.JSONDecodeError as e:
            raise RuntimeError(f"{binary}: its --benchmark_out is not JSON ({e})") from e
    values = {}
    for b in report.get("benchmarks", []):
        if b.get("run_type", "iteration") != "iteration":
            continue  # the aggregates: recomputed here from the runs
        if b.get("error_occurred"):
            raise RuntimeError(f"{binary}: {b['name']}: {b.get('error_message', 'error')}")
        if args.counter not in b:
            raise RuntimeError(f"{binary}: {b['name']} has no counter '{args.counter}'")
        name = b.get("run_name", b["name"])
        values.setdefault(name, []).append(float(b[args.counter]))
    if not values:
        raise RuntimeError(f"{binary}: no benchmark matches --filter '{args.filter}'")
    return values


def collect(args):
    """results[i][benchmark] = one list of repetition values per round, i the
    binary's place on the command line (a binary given twice, an A/A run, is
    two places)."""
    results = [{} for _ in args.binaries]
    with tempfile.TemporaryDirectory() as tmp:
        out_path = os.path.join(tmp, "run.json")
        for r in range(args.rounds):
            for i, binary in enumerate(args.binaries):
                print(f"round {r + 1}/{args.rounds}: {binary}", file=sys.stderr, flush=True)
                for name, vals in run_once(binary, args, out_path).items():
                    results[i].setdefault(name, []).append(vals)
    return results


def fmt(v):
    for scale, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if abs(v) >= scale:
            return f"{v / scale:#.4g}".rstrip(".") + suffix
    return f"{v:#.4g}".rstrip(".")


def report(args, results):
    lines = []
    reference = results[0]
    for name in sorted({n for per in results for n in per}):
        lines.append(name)
        for i, binary in enumerate(args.binaries):
            rounds = results[i].get(name)
            if not rounds:
                lines.append(f"  {binary}: not run")
                continue
            runs = [v for rnd in rounds for v in rnd]
            medians = [statistics.median(rnd) for rnd in rounds]
            text = f"  {binary}: {args.counter} median {fmt(statistics.median(runs))} over {len(runs)} runs;"
            text += " rounds " + " ".join(fmt(m) for m in medians)
            if args.below is not None:
                text += f"; below {fmt(args.below)} in {sum(v < args.below for v in runs)} of {len(runs)}"
            if i > 0 and name in reference:
                ref_medians = [statistics.median(rnd) for rnd in reference[name]]
                ratios = [m / ref for m, ref in zip(medians, ref_medians) if ref]
                text += "; ratio to the first by round " + " ".join(f"{x:.3f}" for x in ratios)
            lines.append(text)
    return "\n".join(lines)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        results = collect(args)
    except (RuntimeError, OSError, ValueError) as e:
        print(f"alternate.py: {e}", file=sys.stderr)
        return 1
    print(report(args, results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
