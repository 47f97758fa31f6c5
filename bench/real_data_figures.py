"""Issue-11 figures on the shared recordings that no evlife command prints.

  PYTHONPATH=build/python /usr/bin/python3 bench/real_data_figures.py [../shared/data] [--plot FILE.png]

1. Past support on evt3_sample.raw: the share of events with at least 3 / 7
   earlier same-polarity events (within 100 ms) at other pixels of their 5x5
   window. With the default N = 5, eq. 8 asks for 7; no past-only estimator
   can give more events a lifetime than have 3. Also counted over either
   polarity in a 7x7 window: what a wider, polarity-blind window could use.
2. Local time quantum of evt3_sample.raw: the time differences between
   events of the same 4x4 pixel block (up to 7 events apart, below 1 ms)
   fall on multiples of ~101 us and nowhere between: under ~25 M events/s
   the readout reaches each region every ~101 us, so a 5x5 window's
   timestamps resolve nothing finer than that.
3. Prediction misses on garfield.mat with predictions that never expire
   (estimator.prediction_expiry_lifetimes = 0): how many predictions err by
   more than 10 ms, how many of those came late, and the median lateness.
4. Warm-up: the share of events with a lifetime in each tenth of a
   recording, default options. The surface starts empty, and eq. 8 asks a
   new edge for 7 past supporters in its window, so the share rises over the
   first lifetimes of each region; a recording only a few lifetimes long is
   mostly warm-up. --plot draws the share against time in median lifetimes
   (bench/doc/warmup.png).
5. Bursts longer than the burst window: on stripes.mat, the events that
   get a lifetime with followers chaining (the default) and not within 2
   lifetimes of the arrival only (burst_span_lifetimes = 2, the rule before),
   how many of them are followers (their pixel's previous lifetime, so more
   than 2 lifetimes after their burst's arrival), and how many events lose
   their lifetime. With --evlife PATH also
   the pixel model's truth (`evlife synth --scene edges-bar --pixel dvs
   --truth`): the share of its edge events that are burst events more than 2
   lifetimes after their burst's first event, at the default 1.5 px blur and
   at 2.5 px.
6. Real background activity (README, *Real background activity*; algo/README.md,
   *Hot pixels*): for the two ROS 2 bags of no moving scene, the event rate by
   tenth, the share of events with no other within +-10 ms in their 3x3
   neighbourhood, the share within 10 ms of the previous event at the same
   pixel, the background rate at pixels under 10 Hz, the share of pixels at
   >= 10 / 100 / 1000 Hz and of the events there, the busiest pixel, and the
   Prophesee's streak at its left border (x < 12, y > 600). For
   sample.aedat4 and the DVXplorer bag, their pixels at >= 200 Hz over the
   recording: how many, how many fire in at least 9 of its tenths, the
   busiest; and the other pixels' share with a lifetime with and without the
   events of the pixels at >= 100 Hz in the input (would a mask help?).
"""
import argparse
import os
import subprocess
import tempfile

import numpy as np

import evlife


def past_support(path, width, height, half_window=2, horizon_us=100_000, either_polarity=False):
    ev = evlife.read(path)
    pad = half_window
    last = np.full((2, height + 2 * pad, width + 2 * pad), np.iinfo(np.int64).min // 2, np.int64)
    t = ev["t"].astype(np.int64)
    x = ev["x"].astype(np.int64) + pad
    y = ev["y"].astype(np.int64) + pad
    p = (ev["p"] > 0).astype(np.int64)
    side = 2 * half_window + 1
    support = np.empty(len(t), np.int32)
    for i in range(len(t)):
        rows, cols = slice(y[i] - pad, y[i] + pad + 1), slice(x[i] - pad, x[i] + pad + 1)
        window = np.maximum(last[0, rows, cols], last[1, rows, cols]) if either_polarity else last[p[i], rows, cols]
        recent = window > t[i] - horizon_us
        support[i] = recent.sum() - recent[side // 2, side // 2]
        last[p[i], y[i], x[i]] = t[i]
    return support


def local_time_quantum(path, block_px=4, neighbours=7, horizon_us=1000):
    ev = evlife.read(path)
    t = ev["t"].astype(np.int64)
    block = (ev["y"].astype(np.int64) // block_px) * 100_000 + ev["x"].astype(np.int64) // block_px
    order = np.lexsort((t, block))
    block, t = block[order], t[order]
    diffs = []
    for k in range(1, neighbours + 1):
        d = (t[k:] - t[:-k])[block[k:] == block[:-k]]
        diffs.append(d[(d > 50) & (d < horizon_us)])
    d = np.concatenate(diffs)
    period = np.median(d[d < 150])  # the first multiple
    phase = np.abs(d / period - np.round(d / period)) * period
    return period, np.mean(phase <= 20), len(d)


def pixel_order(out, width):
    """Indices that sort events by pixel and polarity, then time, and the sorted keys."""
    key = (out["y"].astype(np.int64) * width + out["x"].astype(np.int64)) * 2 + (out["p"] > 0)
    order = np.lexsort((out["t"].astype(np.int64), key))
    return order, key[order]


def chained_followers(chained, unchained, width):
    """Events with a lifetime in `chained` and not in `unchained`, those of
    them that inherit their pixel's previous event's lifetime (followers),
    and the events that lose their lifetime."""
    gained = (chained["lifetime"] > 0) & (unchained["lifetime"] <= 0)
    lost = (chained["lifetime"] <= 0) & (unchained["lifetime"] > 0)
    order, key = pixel_order(chained, width)
    lifetime = chained["lifetime"][order]
    inherits = np.concatenate([[False], (key[1:] == key[:-1]) & (lifetime[1:] == lifetime[:-1])]) & (lifetime > 0)
    return gained.sum(), (gained[order] & inherits).sum(), lost.sum()


def late_burst_share(truth_csv, width):
    """Share of a synthetic scene's edge events that are burst events more than
    2 true lifetimes after their burst's first event (`evlife synth --truth`)."""
    tr = np.genfromtxt(truth_csv, delimiter=",", names=True)
    edge = tr[tr["noise"] == 0]
    order, key = pixel_order({"x": edge["x"], "y": edge["y"], "p": edge["p"], "t": edge["t_us"]}, width)
    t, first, lifetime = edge["t_us"][order], edge["burst_index"][order] == 0, edge["lifetime_us"][order]
    start = np.maximum.accumulate(np.where(first, np.arange(len(t)), 0))  # the burst's first event
    late = ~first & (key[start] == key) & (t - t[start] > 2 * lifetime)
    return np.mean(late)


def synthetic_late_burst_share(evlife_cli, blur_px):
    """late_burst_share() of `evlife synth --scene edges-bar --pixel dvs` (0.6 s, 346x260)."""
    with tempfile.TemporaryDirectory() as tmp:
        events, truth = os.path.join(tmp, "scene.txt"), os.path.join(tmp, "truth.csv")
        subprocess.run([evlife_cli, "synth", "-o", events, "--truth", truth, "--scene", "edges-bar", "--sensor",
                        "346x260", "--duration", "0.6", "--pixel", "dvs", "--edge-blur-px", str(blur_px), "-q"],
                       check=True)
        return late_burst_share(truth, 346)


def sensor_of(path):
    """The sensor `evlife process` uses for the file: the one it states, else
    its events' extent (a .mat states none: Reader.sensor is None)."""
    return evlife.scan(path)["sensor"]


def pixel_rates(ev, width):
    """Each event's pixel (y * width + x), the events per pixel and the recording's length in s."""
    pixel = ev["y"].astype(np.int64) * width + ev["x"].astype(np.int64)
    t = ev["t"].astype(np.int64)
    return pixel, np.bincount(pixel), (t[-1] - t[0]) * 1e-6


def isolated_share(ev, width, horizon_us=10_000):
    """Share of events with no other event (either polarity) within +-horizon_us
    at their pixel or its 8 neighbours."""
    t = ev["t"].astype(np.int64) - int(ev["t"][0])
    stride = width + 2  # a one-pixel border, so that the neighbours' keys never wrap
    key = (ev["y"].astype(np.int64) + 1) * stride + ev["x"].astype(np.int64) + 1
    span = int(t[-1]) + 2 * horizon_us + 1
    packed = np.sort(key * span + t + horizon_us)
    has_neighbour = np.zeros(len(t), bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            base = (key + dy * stride + dx) * span + t + horizon_us
            n = np.searchsorted(packed, base + horizon_us, "right") - np.searchsorted(packed, base - horizon_us, "left")
            has_neighbour |= n > (1 if dx == dy == 0 else 0)  # the event itself
    return 1.0 - np.mean(has_neighbour)


def static_scene_figures(path, name):
    ev = evlife.read(path)
    width, height = sensor_of(path)
    pixel, count, seconds = pixel_rates(ev, width)
    t = ev["t"].astype(np.int64) - int(ev["t"][0])
    tenths = np.bincount(time_bins(t, 10), minlength=10)
    order = np.lexsort((t, pixel))
    repeat = (pixel[order][1:] == pixel[order][:-1]) & (np.diff(t[order]) < 10_000)
    rate = count / seconds
    hot_event = rate[pixel] >= 10
    print(f"{name}: {len(t)} events over {seconds:.2f} s; tenths within {np.max(np.abs(tenths / tenths.mean() - 1)):.0%} "
          f"of the mean; {isolated_share(ev, width):.0%} with no other event within +-10 ms in their 3x3 "
          f"neighbourhood; {np.sum(repeat) / len(t):.0%} within 10 ms of the previous event at their pixel")
    print(f"{name}: background activity {np.sum(~hot_event) / seconds / (width * height):.3f} Hz/px (pixels under "
          f"10 Hz); pixels at >= 10 / 100 / 1000 Hz: "
          + " / ".join(f"{np.sum(rate >= hz) / (width * height):.1e}" for hz in (10, 100, 1000))
          + f" of the pixels, {np.mean(hot_event):.0%} of the events; the busiest {rate.max():.0f} Hz")
    return ev, t


def hot_pixels_of_a_recording(path, name, min_hz=200):
    ev = evlife.read(path)
    sensor = sensor_of(path)
    pixel, count, seconds = pixel_rates(ev, sensor[0])
    t = ev["t"].astype(np.int64) - int(ev["t"][0])
    hot = np.flatnonzero(count >= min_hz * seconds)
    tenth = time_bins(t, 10)
    steady = sum(len(np.unique(tenth[pixel == q])) >= 9 for q in hot)
    print(f"{name}: {len(hot)} pixels at >= {min_hz} Hz over its {seconds:.2f} s, {steady} of them firing in at "
          f"least 9 of its tenths; the busiest {count.max() / seconds:.0f} Hz")
    # Would a mask help? The other pixels' share with and without the busy
    # pixels' events (>= 100 Hz: the summary's `pixels >= 100 Hz`) in the input.
    busy = count[pixel] >= 100 * seconds
    kept = evlife.process(ev, sensor)["lifetime"][~busy] > 0
    masked = evlife.process(ev[~busy], sensor)["lifetime"] > 0
    print(f"{name}: the {len(kept)} events of its other pixels than the {np.sum(count >= 100 * seconds)} at "
          f">= 100 Hz, share with a lifetime {np.mean(kept):.4f}; with those pixels' events removed before the "
          f"estimator (a mask) {np.mean(masked):.4f}, {np.sum(kept != masked)} events differ")


def time_bins(t, bins):
    """Each event's bin: equal spans of the recording, t from 0."""
    return np.minimum(t * bins // max(1, t[-1] + 1), bins - 1)


def share_by_bin(t, lifetime, bins):
    """Each event's bin (time_bins()) and the share with a lifetime in each bin."""
    k = time_bins(t, bins)
    return k, [np.mean(lifetime[k == b] > 0) for b in range(bins)]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("data", nargs="?", default="../shared/data", help="the shared data folder")
    parser.add_argument("--plot", metavar="FILE.png", help="draw the warm-up figure (4) into FILE.png")
    parser.add_argument("--evlife", metavar="PATH", help="the evlife tool, for the pixel model's burst tails (5)")
    args = parser.parse_args()
    data = args.data
    if not os.path.isdir(f"{data}/reference"):
        raise SystemExit(f"real_data_figures: {data} is not the shared data folder (no reference/ in it)")
    support = past_support(f"{data}/evt3/evt3_sample.raw", 1280, 720)
    print(f"evt3_sample.raw: {np.mean(support >= 3):.3f} of events have >= 3 past same-polarity "
          f"events in their 5x5 window, {np.mean(support >= 7):.3f} have >= 7")
    wide = past_support(f"{data}/evt3/evt3_sample.raw", 1280, 720, half_window=3, either_polarity=True)
    print(f"evt3_sample.raw: counting either polarity in a 7x7 window, {np.mean(wide >= 3):.3f} have >= 3, "
          f"{np.mean(wide >= 7):.3f} have >= 7")
    period, on_grid, pairs = local_time_quantum(f"{data}/evt3/evt3_sample.raw")
    print(f"evt3_sample.raw: of {pairs} time differences 50 us - 1 ms within 4x4-pixel blocks, "
          f"{on_grid:.3f} lie within 20 us of a multiple of {period:.1f} us")

    path = f"{data}/reference/garfield.mat"
    ev = evlife.read(path)
    out = evlife.LifetimeEstimator(sensor_of(path), prediction_expiry_lifetimes=0).process(ev)
    err = out["prediction_error"][np.isfinite(out["prediction_error"])]
    miss = err[np.abs(err) > 10_000]
    print(f"garfield.mat, predictions never expiring: {len(err)} predictions, "
          f"{1 - len(miss) / len(err):.3f} below 10 ms; of the {len(miss)} misses "
          f"{np.mean(miss > 0):.2f} came late, by a median {np.median(miss[miss > 0]) / 1000:.1f} ms")

    curves = []
    for name in ("rpg_txt/slider_depth_events_chunk.txt", "evt3/evt3_sample.raw", "aedat4/sample.aedat4",
                 "reference/stripes.mat"):
        out = evlife.process(f"{data}/{name}")
        t = out["t"].astype(np.int64)
        t -= t[0]
        lifetime = out["lifetime"]
        curves.append((name.split("/")[-1], t, lifetime))
        tenth, shares = share_by_bin(t, lifetime, 10)
        print(f"{name.split('/')[-1]}: share with a lifetime by tenth of its {t[-1] / 1000:.1f} ms: "
              + " ".join(f"{v:.2f}" for v in shares) + f"; whole file {np.mean(lifetime > 0):.3f}, "
              f"last 70 % {np.mean(lifetime[tenth >= 3] > 0):.3f}")
    if args.plot:
        plot_warmup(curves, args.plot)

    stripes = f"{data}/reference/stripes.mat"
    gained, followers, lost = chained_followers(evlife.process(stripes),
                                                evlife.process(stripes, burst_span_lifetimes=2), 128)
    print(f"stripes.mat, followers chaining against burst_span_lifetimes 2: {gained} events gain a lifetime, "
          f"{followers} of them as followers (their pixel's previous lifetime); {lost} lose theirs")
    for bag in ("test_data_evt3_trigger", "test_data_libcaer_rollover"):
        path = f"{data}/rosbag/{bag}"
        ev, _ = static_scene_figures(path, bag)
        if bag == "test_data_evt3_trigger":
            streak = (ev["x"] < 12) & (ev["y"] > 600)
            lifetime = evlife.process(path)["lifetime"]
            print(f"{bag}: its left-border streak (x < 12, y > 600) holds {np.mean(streak):.1%} of the events, "
                  f"{np.mean(lifetime[streak] > 0):.1%} of them with a lifetime")
    hot_pixels_of_a_recording(f"{data}/aedat4/sample.aedat4", "sample.aedat4")
    hot_pixels_of_a_recording(f"{data}/rosbag/test_data_libcaer_rollover", "test_data_libcaer_rollover")

    if args.evlife:
        for blur in (1.5, 2.5):
            share = synthetic_late_burst_share(args.evlife, blur)
            print(f"pixel model (edges-bar, dvs, blur {blur} px): {100 * share:.4f} % of the edge events come "
                  f"more than 2 lifetimes after their burst's first event")

def plot_warmup(curves, path):
    """Share with a lifetime in 20 bins of each recording, against the time
    since its first event in median lifetimes."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.6), dpi=110)
    for name, t, lifetime in curves:
        tau = np.median(lifetime[lifetime > 0])
        _, share = share_by_bin(t, lifetime, 20)
        centres = (np.arange(20) + 0.5) * (t[-1] + 1) / 20
        ax.plot(centres / tau, share, marker=".", label=f"{name} ({t[-1] / 1000:.0f} ms)")
    ax.set_xscale("log")
    ax.set_xlabel("time since the first event, in median lifetimes")
    ax.set_ylabel("share with a lifetime")
    ax.set_ylim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Warm-up: the surface starts empty", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
