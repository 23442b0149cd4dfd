#!/usr/bin/python3
"""Figures of a swing calibration (crane_calibrate swing --out DIR, docs/calibration.md): the measured
swing of each fitted segment with the model's replay, and the residual swing of every shaper against
the frequency error, the band and the tolerance marked.

Usage: plot_calibration.py --dir DIR [--band 0.15] [--tolerance 0.05]   (writes DIR/calibration.png)
"""
import argparse
import csv
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = [line for line in f if not line.startswith("#")]
    reader = csv.reader(rows)
    header = next(reader)
    columns = {name: [] for name in header}
    for row in reader:
        for name, cell in zip(header, row):
            columns[name].append(float(cell))
    return header, columns


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--dir", required=True)
    parser.add_argument("--band", type=float, default=0.15)
    parser.add_argument("--tolerance", type=float, default=0.05)
    args = parser.parse_args()
    _, fit = read(os.path.join(args.dir, "fit.csv"))
    header, shapers = read(os.path.join(args.dir, "shapers.csv"))
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(10, 8))
    segments = sorted(set(int(s) for s in fit["segment"]))
    for k in segments:
        index = [i for i, s in enumerate(fit["segment"]) if int(s) == k]
        t = [fit["t"][i] for i in index]
        top.plot(t, [math.degrees(fit["measured"][i]) for i in index], ".", markersize=2, label=f"segment {k} measured")
        top.plot(t, [math.degrees(fit["model"][i]) for i in index], "-", linewidth=1, label=f"segment {k} model")
    top.set_xlabel("t [s]")
    top.set_ylabel("swing [deg]")
    top.set_title("fitted swing segments")
    top.legend(fontsize=7, ncol=2)
    ratio = shapers["ratio"]
    for name in header[1:]:
        style = "--" if name.startswith("zv_nominal") else "-"
        width = 2.5 if "recommended" in name else 1.2
        bottom.plot(ratio, [100.0 * v for v in shapers[name]], style, linewidth=width, label=name)
    bottom.axvspan(1.0 - args.band, 1.0 + args.band, color="0.9", label=f"band +-{100 * args.band:.0f} %")
    bottom.axhline(100.0 * args.tolerance, color="k", linewidth=0.8, label=f"tolerance {100 * args.tolerance:.0f} %")
    bottom.set_xlabel("swing frequency / fitted frequency")
    bottom.set_ylabel("residual swing [% of unshaped]")
    bottom.set_ylim(0.0, 60.0)
    bottom.set_title("shapers designed at the fitted frequency (zv_nominal: ZV on sqrt(g/L))")
    bottom.legend(fontsize=8)
    figure.tight_layout()
    out = os.path.join(args.dir, "calibration.png")
    figure.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
