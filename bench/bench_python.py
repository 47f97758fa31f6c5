#!/usr/bin/python3
"""Speed of the Python module (issue 14), printed as tables; not a test.

  PYTHONPATH=build/python /usr/bin/python3 bench/bench_python.py [--build build] [--repetitions 5]

1. LifetimeEstimator.process on a NumPy array vs the C++ estimator alone
   (build/bench/bench_estimator, Google Benchmark, CPU time), same recordings,
   same options (the struct defaults, as bench_estimator uses them: an empty
   config file); rounds alternate the two, best of 3 each.
2. evlife.batch.process_files on a LocalCluster of 2 workers vs 1 worker over
   synthetic recordings made by `evlife synth` (alternating runs; cluster
   start-up excluded, then included).
3. evlife.batch.process_slices (4 time slices of one recording in parallel)
   against one pass: how many events change label (noise/edge) or lifetime,
   by warm-up length.
4. evlife.process_file as it runs by default (decoded ahead, written behind,
   each on a thread of its own) vs one_thread=True, per output format, on one
   synthetic recording (`evlife synth --scene mixed`, 346x260, HDF5 input):
   alternating runs, wall time, outputs compared byte for byte.

5. evlife.batch.process_slices' tasks over 4 and 16 slices of one HDF5
   recording, each starting at its warm-up by a binary search on t against
   each decoding the file from its start (alternating runs, one at a time).
6. evlife.read(h5, from_s=9) on a 10 s HDF5 recording (starts by a binary
   search on t) against decoding the file chunk by chunk (evlife.open) and
   dropping the events before 9 s, as every reader did before (and the
   formats without a search still do); arrays compared.

--only N runs part N alone (e.g. --only 4: a minute).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import evlife
from evlife import batch

RECORDINGS = ["stripes", "garfield"]


def cpp_speeds(build, repetitions):
    """Best events/s (least CPU time) of BM_Estimator_N5_reg per recording."""
    exe = os.path.join(build, "bench", "bench_estimator")
    out = subprocess.run([exe, "--benchmark_filter=BM_Estimator_N5_reg/(%s)$" % "|".join(RECORDINGS),
                          "--benchmark_repetitions=%d" % repetitions, "--benchmark_format=json"],
                         capture_output=True, text=True, check=True).stdout
    speeds = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("run_type") == "iteration":
            name = b["run_name"].split("/")[-1]
            speeds[name] = max(speeds.get(name, 0.0), b["items_per_second"])
    return speeds


def python_speeds(recordings, repetitions, empty_config):
    """Best events/s (least CPU time) of LifetimeEstimator.process on the whole array."""
    speeds = {}
    for name, events in recordings.items():
        est = evlife.LifetimeEstimator(sensor=(128, 128), config=empty_config)
        cpu = []
        for _ in range(repetitions):
            est.reset()
            t0 = time.process_time()
            est.process(events)
            cpu.append(time.process_time() - t0)
        speeds[name] = len(events) / min(cpu)
    return speeds


def compare_estimators(build, data_dir, rounds, empty_config):
    """Rounds alternate C++ and Python (3 repetitions each, best kept), so that
    the load of a shared machine hits both alike; returns per-recording lists."""
    recordings = {n: evlife.read(os.path.join(data_dir, "reference", n + ".mat")) for n in RECORDINGS}
    cpp = {n: [] for n in RECORDINGS}
    py = {n: [] for n in RECORDINGS}
    for _ in range(rounds):
        c = cpp_speeds(build, 3)
        p = python_speeds(recordings, 3, empty_config)
        for n in RECORDINGS:
            cpp[n].append(c[n])
            py[n].append(p[n])
    return cpp, py


def make_recordings(cli, folder, count):
    paths = []
    for i in range(count):
        p = os.path.join(folder, "synth_%d.txt" % i)
        subprocess.run([cli, "synth", "-o", p, "--scene", "edges", "--sensor", "240x180",
                        "--duration", "6", "--seed", str(i + 1), "--quiet"], check=True)
        paths.append(p)
    return paths


def compare_batch(paths, out_dir, repetitions, dask_defaults=False):
    """Wall seconds of process_files on 1 and on 2 workers, alternating, and
    each cluster's start-up time."""
    from distributed import Client
    clients, startup, runs = {}, {}, {1: [], 2: []}
    try:
        for workers in (1, 2):
            t0 = time.perf_counter()
            if dask_defaults:  # Dask's own worker housekeeping, for comparison
                from distributed import LocalCluster
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=":0")
            else:
                cluster = batch.local_cluster(workers)  # as process_files makes it
            clients[workers] = Client(cluster)
            clients[workers].run(lambda: __import__("evlife"))  # workers import the module once
            startup[workers] = time.perf_counter() - t0
        for _ in range(repetitions):
            for workers in (1, 2):
                t0 = time.perf_counter()
                table = batch.process_files(paths, out_dir, scheduler=clients[workers],
                                            progress=False)
                runs[workers].append(time.perf_counter() - t0)
                assert not table.failed, table.failed
    finally:
        for c in clients.values():
            cluster = c.cluster
            c.close()
            cluster.close()
    return runs, startup, sum(r.events for r in table)


def cli_parallel_seconds(cli, paths, out_dir, parallel):
    """The machine's own bound: the same files through `evlife process`, `parallel` at a time."""
    os.makedirs(out_dir, exist_ok=True)
    t0 = time.perf_counter()
    pending = list(paths)
    running = []
    while pending or running:
        while pending and len(running) < parallel:
            p = pending.pop(0)
            out = os.path.join(out_dir, os.path.basename(p) + ".bin")
            running.append(subprocess.Popen([cli, "process", p, "-o", out, "-q", "--one-thread"]))
        running[0].wait()
        assert running.pop(0).returncode == 0
    return time.perf_counter() - t0


def slice_differences(data_dir, warmups_ms, slices=4):
    """Rows: recording, length, warm-up, label differs %, lifetime > 1 % off (% of edge events)."""
    import numpy as np
    from distributed import Client, LocalCluster
    rows = []
    with tempfile.TemporaryDirectory() as tmp, \
            LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        for name in RECORDINGS:
            path = os.path.join(data_dir, "reference", name + ".mat")
            one = evlife.process(path)
            for warm in warmups_ms:
                out = os.path.join(tmp, "slices.bin")
                batch.process_slices(path, out, slices=slices, warmup_ms=warm, scheduler=client,
                                     progress=False)
                sliced, _ = evlife.read_augmented(out)
                a, b = sliced["lifetime"], one["lifetime"]
                both = (a > 0) & (b > 0)
                rel = np.abs(a[both] - b[both]) / b[both]
                rows.append((name, (one["t"][-1] - one["t"][0]) / 1e6, warm,
                             100 * ((a > 0) != (b > 0)).mean(), 100 * (rel > 0.01).mean()))
    return rows


def compare_process_file(cli, folder, repetitions, seconds=10):
    """Rows: format, overlapped s, one-thread s (medians), median ratio (min..max), same bytes."""
    scene = os.path.join(folder, "scene.h5")
    subprocess.run([cli, "synth", "--scene", "mixed", "--sensor", "346x260", "--duration",
                    str(seconds), "-o", scene, "--quiet"], check=True)
    rows = []
    for ext in ("bin", "csv", "h5"):
        runs = {False: [], True: []}
        for _ in range(repetitions):
            for one_thread in (False, True):
                out = os.path.join(folder, "%s.%s" % ("one" if one_thread else "over", ext))
                t0 = time.perf_counter()
                info = evlife.process_file(scene, out, one_thread=one_thread)
                runs[one_thread].append(time.perf_counter() - t0)
        with open(os.path.join(folder, "over." + ext), "rb") as a, \
                open(os.path.join(folder, "one." + ext), "rb") as b:
            same = a.read() == b.read()
        ratios = [o / v for v, o in zip(runs[False], runs[True])]
        rows.append((ext, statistics.median(runs[False]), statistics.median(runs[True]),
                     statistics.median(ratios), min(ratios), max(ratios), same))
    return rows, info["events"]


def slice_seconds(cli, folder, repetitions, seconds=20, warmup_us=100_000):
    """Per slice count (4, 16): the seconds of every slice's task
    (evlife.batch's _process_time_range, run here one after the other) over an
    HDF5 recording, each starting at its warm-up by a binary search on t and
    each decoding from the file's start; medians of alternating runs."""
    from evlife import _evlife as core
    h5 = os.path.join(folder, "long.h5")
    subprocess.run([cli, "synth", "--scene", "mixed", "--sensor", "346x260", "--duration",
                    str(seconds), "-o", h5, "--quiet"], check=True)
    info = core.scan(h5, None)
    t0, t1 = info["t_first"], info["t_last"] + 1
    part = os.path.join(folder, "part.bin")
    result = {}
    for slices in (4, 16):
        cuts = [t0 + (t1 - t0) * k // slices for k in range(slices)] + [t1]
        per_slice = {True: [[] for _ in range(slices)], False: [[] for _ in range(slices)]}
        for _ in range(repetitions):
            for k in range(slices):
                for search in (True, False):
                    start = time.perf_counter()
                    core._process_time_range(h5, part, info["sensor"], cuts[k], cuts[k + 1],
                                             warmup_us, skip_by_search=search)
                    per_slice[search][k].append(time.perf_counter() - start)
        result[slices] = {search: [statistics.median(r) for r in runs]
                          for search, runs in per_slice.items()}
    return result, info["events"]


def from_seconds(cli, folder, repetitions, seconds=10, from_s=9.0):
    """Seconds to read the events from from_s on: by the search (from_s=) and
    by decoding and dropping (evlife.open, chunks); medians of alternating
    runs, the two arrays equal."""
    import numpy as np
    h5 = os.path.join(folder, "from.h5")
    subprocess.run([cli, "synth", "--scene", "mixed", "--sensor", "346x260", "--duration",
                    str(seconds), "-o", h5, "--quiet"], check=True)

    def decode_and_drop():
        kept, cut = [], None
        with evlife.open(h5, chunk_events=1 << 16) as r:
            for chunk in r:
                cut = chunk["t"][0] + int(from_s * 1e6) if cut is None else cut
                kept.append(chunk[chunk["t"] >= cut])
        return np.concatenate(kept)

    runs = {"search": [], "decode": []}
    for _ in range(repetitions):
        for how, read in (("search", lambda: evlife.read(h5, from_s=from_s)), ("decode", decode_and_drop)):
            t0 = time.perf_counter()
            read()
            runs[how].append(time.perf_counter() - t0)
    searched = evlife.read(h5, from_s=from_s)
    same = np.array_equal(searched, decode_and_drop())
    ratios = [d / s for s, d in zip(runs["search"], runs["decode"])]
    total = evlife.scan(h5)["events"]
    return (statistics.median(runs["search"]), statistics.median(runs["decode"]), statistics.median(ratios),
            min(ratios), max(ratios), same, len(searched), total)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data"))
    ap.add_argument("--repetitions", type=int, default=5)
    ap.add_argument("--files", type=int, default=6)
    ap.add_argument("--only", type=int, choices=(1, 2, 3, 4, 5, 6), help="run this part alone")
    ap.add_argument("--dask-defaults", action="store_true",
                    help="batch on a LocalCluster with Dask's default housekeeping (profiler, monitors)")
    args = ap.parse_args()

    print("load average at the start: %.2f %.2f %.2f (2 cores)" % os.getloadavg())
    run = (lambda part: args.only in (None, part))
    cli = os.path.join(args.build, "engine", "evlife")
    with tempfile.TemporaryDirectory() as tmp:
        if run(1):
            empty = os.path.join(tmp, "struct_defaults.yaml")
            open(empty, "w").close()
            cpp, py = compare_estimators(args.build, args.data, args.repetitions, empty)
            print("LifetimeEstimator.process vs the C++ estimator (N = 5, regularized, struct defaults; "
                  "CPU time; %d alternating rounds of best-of-3)" % args.repetitions)
            print("| recording | C++ (bench_estimator), median of rounds | Python process(array) | "
                  "Python / C++, median of the rounds' ratios (min..max) |")
            print("|---|---|---|---|")
            for n in RECORDINGS:
                ratios = [p / c for p, c in zip(py[n], cpp[n])]
                print("| %s | %.2f M ev/s | %.2f M ev/s | %.3f (%.3f..%.3f) |" % (
                    n, statistics.median(cpp[n]) / 1e6, statistics.median(py[n]) / 1e6,
                    statistics.median(ratios), min(ratios), max(ratios)))
            sys.stdout.flush()

        if run(2):
            paths = make_recordings(cli, tmp, args.files)
            runs, startup, events = compare_batch(paths, os.path.join(tmp, "out"), args.repetitions,
                                                  args.dask_defaults)
            cli_runs = {1: [], 2: []}
            for _ in range(args.repetitions):
                for parallel in (1, 2):
                    cli_runs[parallel].append(cli_parallel_seconds(cli, paths, os.path.join(tmp, "cli"), parallel))
            cli_ratios = [a / b for a, b in zip(cli_runs[1], cli_runs[2])]
            one, two = statistics.median(runs[1]), statistics.median(runs[2])
            ratios = [a / b for a, b in zip(runs[1], runs[2])]
            print()
            print("evlife.batch.process_files, %d files, %.1f M events (wall time, %d alternating runs)"
                  % (len(paths), events / 1e6, args.repetitions))
            print("| workers | seconds (median) | M events/s | speed-up: median of the runs' ratios (min..max) | cluster start-up |")
            print("|---|---|---|---|---|")
            print("| 1 | %.2f | %.2f | 1 | %.1f s |" % (one, events / one / 1e6, startup[1]))
            print("| 2 | %.2f | %.2f | %.2f (%.2f..%.2f) | %.1f s |" % (
                two, events / two / 1e6, statistics.median(ratios), min(ratios), max(ratios), startup[2]))
            print("| 2 vs 1, start-up included (one call) | | | %.2f | |" % (
                (one + startup[1]) / (two + startup[2])))
            print("| reference: `evlife process` on the same files, 2 at a time vs 1 (this machine's bound now) "
                  "| %.2f / %.2f | | %.2f (%.2f..%.2f) | |" % (
                      statistics.median(cli_runs[1]), statistics.median(cli_runs[2]),
                      statistics.median(cli_ratios), min(cli_ratios), max(cli_ratios)))

        if run(3):
            print()
            print("evlife.batch.process_slices: 4 slices in parallel vs one pass (default options)")
            print("| recording | length | warm-up | noise/edge label differs | lifetime off by > 1 % (edge events) |")
            print("|---|---|---|---|---|")
            for name, length, warm, label, off in slice_differences(args.data, (10, 100, 300)):
                print("| %s | %.2f s | %d ms | %.2f %% | %.2f %% |" % (name, length, warm, label, off))
        if run(4):
            rows, events = compare_process_file(cli, tmp, args.repetitions)
            print()
            print("evlife.process_file, overlapped (default) vs one_thread=True, %.2f M events "
                  "(synth --scene mixed, 346x260, 10 s, .h5 input; wall time, %d alternating runs)"
                  % (events / 1e6, args.repetitions))
            print("| output | overlapped s | one_thread s | one_thread / overlapped, median (min..max) | same bytes |")
            print("|---|---|---|---|---|")
            for ext, over, one, ratio, lo, hi, same in rows:
                print("| .%s | %.2f | %.2f | %.2f (%.2f..%.2f) | %s |" % (ext, over, one, ratio, lo, hi,
                                                                         "yes" if same else "NO"))
        if run(5):
            result, events = slice_seconds(cli, tmp, args.repetitions)
            print()
            print("evlife.batch.process_slices' tasks over a %.1f M-event HDF5 recording (synth "
                  "--scene mixed 346x260, 20 s; its event rate rises over time), 100 ms warm-up, "
                  "run one at a time; wall seconds, medians of %d alternating runs"
                  % (events / 1e6, args.repetitions))
            print("| slices | all tasks: binary search on t / decoded from the start (ratio) | "
                  "first slice | last slice |")
            print("|---|---|---|---|")
            for slices, r in result.items():
                cells = ["%.2f / %.2f (%.2f)" % (sum(r[True]), sum(r[False]), sum(r[False]) / sum(r[True]))]
                for k in (0, slices - 1):
                    cells.append("%.2f / %.2f (%.2f)" % (r[True][k], r[False][k], r[False][k] / r[True][k]))
                print("| %d | %s |" % (slices, " | ".join(cells)))
        if run(6):
            search, decode, ratio, lo, hi, same, kept, total = from_seconds(cli, tmp, args.repetitions)
            print()
            print("The last second of a %.2f M-event HDF5 recording (synth --scene mixed 346x260, 10 s; "
                  "%d events from 9 s on; wall time, %d alternating runs)" % (total / 1e6, kept, args.repetitions))
            print("| evlife.read(h5, from_s=9): search | decode and drop (evlife.open) | ratio, median (min..max) | same events |")
            print("|---|---|---|---|")
            print("| %.3f s | %.3f s | %.2f (%.2f..%.2f) | %s |" % (search, decode, ratio, lo, hi, "yes" if same else "NO"))
    print("load average at the end: %.2f %.2f %.2f (2 cores)" % os.getloadavg())


if __name__ == "__main__":
    main()
