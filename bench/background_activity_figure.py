#!/usr/bin/env python3
"""How much background activity each configuration tolerates: the pixel model's
four scenes (accuracy_sweep) at rising noise rates, with the defaults and with a
preset, plotted as the share of noise labelled noise and the share of edge events
with a lifetime against the rate (the issue's 97 % noise floor drawn).

    python3 bench/background_activity_figure.py --sweep build/bench/accuracy_sweep \\
        --config config/faint-texture.yaml --plot bench/doc/background_activity.png

Prints one row per rate and configuration. A 0.6 s scene shows the base rate
only; the runaway of a band that is too wide at 10 Hz/px takes seconds
(tests/test_long_recordings.cpp).
"""
import argparse

import sweep_table  # bench/, beside this script

RATES_HZ_PER_PX = [0.1, 0.3, 1.0, 2.0, 3.0, 5.0, 10.0]
NOISE_FLOOR = 0.97


def sweep(binary, rate, config):
    """[(scene, share, noise)] of accuracy_sweep's four rows at `rate`."""
    args = [binary, "--noise-rate", str(rate)] + (["--config", config] if config else [])
    out = sweep_table.run_sweep("background_activity_figure", args)
    columns = sweep_table.header_columns(out)
    rows = []
    for line in out.strip().split("\n")[-4:]:
        scene, (share, noise) = sweep_table.row_values(line, columns, ["share%", "noise%"])
        rows.append((scene, share / 100.0, noise / 100.0))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sweep", default="build/bench/accuracy_sweep", help="accuracy_sweep binary")
    ap.add_argument("--config", default="config/faint-texture.yaml", help="the preset to compare")
    ap.add_argument("--plot", help="write the figure here (PNG)")
    opts = ap.parse_args()
    curves = {}
    for label, config in (("defaults", None), (opts.config, opts.config)):
        for rate in RATES_HZ_PER_PX:
            rows = sweep(opts.sweep, rate, config)
            curves.setdefault(label, []).append((rate, rows))
            noise = [r[2] for r in rows]
            share = [r[1] for r in rows]
            print(f"{label:28s} {rate:5.1f} Hz/px: noise labelled noise {100 * min(noise):.2f}-{100 * max(noise):.2f} %, "
                  f"edge events with a lifetime {100 * min(share):.2f}-{100 * max(share):.2f} %")
    if not opts.plot:
        return
    import plotting  # bench/, beside this script
    fig, (ax_noise, ax_share) = plotting.two_panels()
    for (label, points), colour in zip(curves.items(), ("tab:blue", "tab:orange")):
        rates = [p[0] for p in points]
        for scene in range(4):
            name = points[0][1][scene][0]
            style = "-" if "edges" in name else "--"
            light = "dim" if "dim" in name else "normal"
            what = ("edges" if "edges" in name else "bar") + ", " + light
            ax_noise.plot(rates, [100 * p[1][scene][2] for p in points], style, color=colour, marker="o",
                          markersize=3, alpha=1.0 if light == "normal" else 0.55, label=f"{label}: {what}")
            ax_share.plot(rates, [100 * p[1][scene][1] for p in points], style, color=colour, marker="o",
                          markersize=3, alpha=1.0 if light == "normal" else 0.55)
    ax_noise.axhline(100 * NOISE_FLOOR, color="grey", linewidth=0.8)
    ax_noise.set_xscale("log")
    ax_noise.set_xlabel("background activity, events / pixel / s")
    ax_noise.set_ylabel("noise labelled noise, %")
    ax_noise.set_title("noise (grey: the 97 % floor)")
    ax_noise.legend(fontsize=6)
    ax_share.set_xscale("log")
    ax_share.set_xlabel("background activity, events / pixel / s")
    ax_share.set_ylabel("edge events with a lifetime, %")
    ax_share.set_title("edges (pixel model, 0.6 s scenes)")
    fig.tight_layout()
    fig.savefig(opts.plot, dpi=110)
    print("wrote", opts.plot)


if __name__ == "__main__":
    main()
