"""How many of a synthetic scene's edge events get a lifetime close to their
truth, and how many one far off: what a share and a median hide when an
estimator gives many events lifetimes several times too long.

  evlife synth -o s.txt --scene edges --sensor 346x260 --duration 0.6 --pixel dvs \\
      --truth truth.csv [pixel options]
  evlife process s.txt -o out.csv [--set ...]
  /usr/bin/python3 bench/truth_error_counts.py truth.csv out.csv --sensor 346x260

A crude count, coarser than accuracy_sweep's scoring: every edge event (noise
and hot-pixel events excluded, burst followers included) at least --border px
inside the sensor and after --after-us, row for row (the truth and the output
hold the same events in the same order, as `evlife process` of a text file
writes them). Printed, in % of those edge events: with a lifetime; within 10 %
and 30 % of the true lifetime; off by more than 100 %; the median and p90
relative error of those with a lifetime; and the share of the noise events
(same region) labelled noise.
"""
import argparse
import sys

import numpy as np


def counts(truth, out, width, height, border_px=5, after_us=50_000):
    """The figures above as a dict (fractions, not %)."""
    if len(truth) != len(out):
        raise ValueError(f"truth has {len(truth)} events, output {len(out)}: not the same recording")
    x, y = truth["x"], truth["y"]
    region = ((truth["t_us"] > after_us) & (x >= border_px) & (x < width - border_px)
              & (y >= border_px) & (y < height - border_px))
    edge = region & (truth["noise"] == 0) & (truth["hot"] == 0)
    n = int(edge.sum())
    if n == 0:
        raise ValueError("no edge event in the scored region")
    lifetime = out["lifetime"][edge]
    true_lifetime = truth["lifetime_us"][edge]
    has = lifetime > 0
    err = np.abs(lifetime[has] - true_lifetime[has]) / true_lifetime[has]
    noise = region & (truth["noise"] == 1)
    return {
        "edge_events": n,
        "with_lifetime": has.mean(),
        "within_10": (err < 0.1).sum() / n,
        "within_30": (err < 0.3).sum() / n,
        "off_over_100": (err > 1.0).sum() / n,
        "median_error": float(np.median(err)) if err.size else float("nan"),
        "p90_error": float(np.percentile(err, 90)) if err.size else float("nan"),
        "noise_labelled_noise": (out["lifetime"][noise] == 0).mean() if noise.any() else float("nan"),
    }


def read_csv(path, columns):
    return np.genfromtxt(path, delimiter=",", names=True, usecols=columns)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("truth", help="evlife synth --truth CSV")
    ap.add_argument("output", help="evlife process output (.csv) of the same recording")
    ap.add_argument("--sensor", default="346x260", help="WxH (default 346x260)")
    ap.add_argument("--border", type=int, default=5, help="pixels left out at each border (default 5)")
    ap.add_argument("--after-us", type=float, default=50_000, help="events before this are warm-up (default 50000)")
    args = ap.parse_args(argv)
    width, height = (int(v) for v in args.sensor.lower().split("x"))
    truth = read_csv(args.truth, ("t_us", "x", "y", "noise", "lifetime_us", "hot"))
    out = read_csv(args.output, ("lifetime",))
    try:
        c = counts(truth, out, width, height, args.border, args.after_us)
    except ValueError as e:
        sys.exit(f"truth_error_counts: {e}")
    print(f"{c['edge_events']} edge events: {100 * c['with_lifetime']:.2f} % with a lifetime, "
          f"{100 * c['within_10']:.2f} % within 10 %, {100 * c['within_30']:.2f} % within 30 %, "
          f"{100 * c['off_over_100']:.2f} % off by more than 100 %; median error {100 * c['median_error']:.1f} %, "
          f"p90 {100 * c['p90_error']:.0f} %; noise labelled noise {100 * c['noise_labelled_noise']:.2f} %")


if __name__ == "__main__":
    main()
