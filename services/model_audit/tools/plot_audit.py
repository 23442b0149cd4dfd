#!/usr/bin/python3
"""Plots of a crane_audit run: DIR/series.csv -> DIR/fit.png (measured, nominal, extended) and
DIR/residuals.png (residual before and after; held-out part shaded). Usage: plot_audit.py DIR"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    rows = []
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    for row in csv.DictReader(lines):
        rows.append({k: float(v) for k, v in row.items()})
    return rows


def main():
    out = sys.argv[1]
    rows = read(os.path.join(out, "series.csv"))
    step = max(1, len(rows) // 4000)  # keep the PNGs small
    rows = rows[::step]
    t = [r["t"] for r in rows]
    meas = [r["measured"] for r in rows]
    nom = [r["nominal"] for r in rows]
    ext = [r["extended"] for r in rows]
    hold = [r["holdout"] for r in rows]
    before = [m - n if not math.isnan(n) else math.nan for m, n in zip(meas, nom)]
    after = [m - e if not math.isnan(e) else math.nan for m, e in zip(meas, ext)]
    held_start = next((ti for ti, h in zip(t, hold) if h > 0.5), None)

    fig, ax = plt.subplots(figsize=(7, 3.2), dpi=80)
    ax.plot(t, meas, "k.", ms=1.5, label="measured")
    ax.plot(t, nom, "-", lw=0.8, color="tab:red", label="nominal")
    ax.plot(t, ext, "-", lw=0.8, color="tab:blue", label="extended")
    if held_start is not None:
        ax.axvspan(held_start, t[-1], color="0.9", zorder=0, label="held out")
    ax.set_xlabel("t [s]")
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fit.png"))

    fig, ax = plt.subplots(figsize=(7, 3.2), dpi=80)
    ax.plot(t, before, "-", lw=0.6, color="tab:red", label="residual nominal")
    ax.plot(t, after, "-", lw=0.6, color="tab:blue", label="residual extended")
    if held_start is not None:
        ax.axvspan(held_start, t[-1], color="0.9", zorder=0)
    ax.set_xlabel("t [s]")
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "residuals.png"))


if __name__ == "__main__":
    main()
