#!/usr/bin/env python3
"""Which edges a photoreceptor of limited bandwidth lets the estimator resolve:
the pixel model's scenes (accuracy_sweep --bands) at several photoreceptor
cutoffs, the share of edge events with a lifetime and the median lifetime error
per true-lifetime band, plotted against lifetime / time constant (T = 1 / (2 pi
cutoff)), where the curves of all cutoffs should fall together.

    python3 bench/photoreceptor_figure.py --sweep build/bench/accuracy_sweep \\
        --plot bench/doc/photoreceptor.png

Prints one row per cutoff and band (normal-light edges by default, --scene to
pick another of accuracy_sweep's rows). Extra accuracy_sweep arguments after
`--`, e.g. `-- --set estimator.burst_span_timing_noise=10`.
"""
import argparse
import math

import sweep_table  # bench/, beside this script

CUTOFFS_HZ = [3000.0, 1000.0, 300.0, 100.0, 30.0]


def time_constant_us(cutoff_hz):
    return 1e6 / (2.0 * math.pi * cutoff_hz)


def parse_bands(text, scene):
    """[(lo_us, hi_us, share, median)] of the band rows that follow `scene`'s
    "by true lifetime" header in accuracy_sweep --bands output (fractions)."""
    rows, inside = [], False
    columns = sweep_table.header_columns(text)
    for line in text.splitlines():
        if "by true lifetime" in line:
            inside = line.startswith(scene + ",") or line.startswith(scene + " ")
            continue
        if not inside:
            continue
        fields = line.split()
        if not fields or fields[0] != "lifetime":  # the band rows end
            inside = False
            continue
        if fields[1] == ">=":
            lo, hi = float(fields[2]), math.inf
        else:
            lo, hi = (float(v) for v in fields[1].split(".."))
        _, (share, median) = sweep_table.row_values(line, columns, ["share%", "med%"])
        rows.append((lo, hi, share / 100.0, median / 100.0))
    return rows


def sweep(binary, cutoff_hz, scene, extra):
    args = [binary, "--bands", "--pixel", f"cutoff-hz={cutoff_hz:g}"] + extra
    out = sweep_table.run_sweep("photoreceptor_figure", args)
    rows = parse_bands(out, scene)
    if not rows:
        raise SystemExit(f"photoreceptor_figure: no band rows for scene '{scene}' in {' '.join(args)}")
    return rows


def band_centre_us(lo, hi):
    """Geometric centre of a band (the lowest band from half its top, the open
    top band at twice its floor: the scenes' lifetimes span 300 us .. 30 ms)."""
    if not math.isfinite(hi):
        return 2.0 * lo
    return math.sqrt((lo if lo > 0.0 else 0.5 * hi) * hi)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sweep", default="build/bench/accuracy_sweep", help="accuracy_sweep binary")
    ap.add_argument("--scene", default="edges 346x260, 0.6 s, dvs pixels", help="accuracy_sweep row to plot")
    ap.add_argument("--plot", help="write the figure here (PNG)")
    ap.add_argument("extra", nargs="*", help="more accuracy_sweep arguments (after --)")
    opts = ap.parse_args()
    curves = {}
    for cutoff in CUTOFFS_HZ:
        rows = sweep(opts.sweep, cutoff, opts.scene, opts.extra)
        curves[cutoff] = rows
        t_us = time_constant_us(cutoff)
        for lo, hi, share, median in rows:
            band = f"{lo:.0f}..{hi:.0f} us" if math.isfinite(hi) else f">= {lo:.0f} us"
            print(f"{cutoff:6.0f} Hz (T {t_us:7.0f} us)  lifetime {band:16s} tau/T ~{band_centre_us(lo, hi) / t_us:7.2f}: "
                  f"{100 * share:6.2f} % with a lifetime, median error {100 * median:7.2f} %")
    if not opts.plot:
        return
    import plotting  # bench/, beside this script
    fig, (ax_share, ax_error) = plotting.two_panels()
    for cutoff, rows in curves.items():
        t_us = time_constant_us(cutoff)
        x = [band_centre_us(lo, hi) / t_us for lo, hi, _, _ in rows]
        label = f"{cutoff:g} Hz (T = {t_us / 1000:.2g} ms)"
        ax_share.plot(x, [100 * r[2] for r in rows], "-o", markersize=3, label=label)
        ax_error.plot(x, [100 * r[3] for r in rows], "-o", markersize=3, label=label)
    for ax in (ax_share, ax_error):
        ax.set_xscale("log")
        ax.set_xlabel("true lifetime / time constant of ON edges\n(band centres; OFF edges: e^C slower)")
        ax.axvline(2.0, color="grey", linewidth=0.8)
    ax_share.axhline(95.0, color="grey", linewidth=0.8, linestyle="--")
    ax_share.set_ylabel("edge events with a lifetime, %")
    ax_share.set_title("share (grey: 2 T; dashed: the 95 % floor)")
    ax_share.legend(fontsize=7)
    ax_error.set_yscale("log")
    ax_error.axhline(5.0, color="grey", linewidth=0.8, linestyle="--")
    ax_error.set_ylabel("median |lifetime error|, %")
    ax_error.set_title("median error (dashed: the 5 % floor)")
    fig.suptitle(f"{opts.scene}: photoreceptor cutoffs {', '.join(f'{c:g}' for c in CUTOFFS_HZ)} Hz", fontsize=9)
    fig.tight_layout()
    fig.savefig(opts.plot, dpi=110)
    print("wrote", opts.plot)


if __name__ == "__main__":
    main()
