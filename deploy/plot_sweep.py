#!/usr/bin/python3
"""Heat maps of a crane_sim sweep: one PNG per controller, the load mass factor against the cable
length factor of the simulated plant (what the controllers do not know), coloured by the residual
swing over the last 2 s of the move [deg]; a run that never settled is ringed, one whose supervisor
latched a fault is crossed. A grid sweep is drawn as cells, a random set as points.

Usage: plot_sweep.py --csv SWEEP.csv --out DIR   (writes DIR/sweep_<controller>.png)
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    return float(text) if text not in ("", None) else math.nan


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--csv", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    with open(args.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{args.csv}: no cases")
    controllers = sorted({r["controller"] for r in rows})
    resid_all = [number(r["resid_swing_deg"]) for r in rows if not math.isnan(number(r["resid_swing_deg"]))]
    vmax = max(resid_all) if resid_all else 1.0
    for controller in controllers:
        cases = [r for r in rows if r["controller"] == controller]
        x = [number(r["cable_length_factor"]) for r in cases]
        y = [number(r["load_mass_factor"]) for r in cases]
        c = [number(r["resid_swing_deg"]) for r in cases]
        unsettled = [r["settle_s"] == "" for r in cases]
        faulted = [r["latched_faults"] not in ("0", "") for r in cases]
        fig, ax = plt.subplots(figsize=(6.4, 5.0))
        xs, ys = sorted(set(x)), sorted(set(y))
        if len(xs) * len(ys) == len(cases):  # a grid: cells
            grid = [[math.nan] * len(xs) for _ in ys]
            for xi, yi, ci in zip(x, y, c):
                grid[ys.index(yi)][xs.index(xi)] = ci
            mesh = ax.pcolormesh(xs, ys, grid, shading="nearest", cmap="viridis", vmin=0.0, vmax=vmax)
        else:  # a random set: points (friction level and sensor delay vary too; see sweep.csv)
            mesh = ax.scatter(x, y, c=c, cmap="viridis", vmin=0.0, vmax=vmax, s=36, edgecolors="none")
        ax.scatter([xi for xi, u in zip(x, unsettled) if u], [yi for yi, u in zip(y, unsettled) if u], s=90,
                   facecolors="none", edgecolors="red", linewidths=0.8, label="never settled")
        ax.scatter([xi for xi, f in zip(x, faulted) if f], [yi for yi, f in zip(y, faulted) if f], marker="x",
                   color="black", s=40, label="supervisor fault")
        fig.colorbar(mesh, ax=ax, label="residual swing over the last 2 s [deg]")
        ax.set_xlabel("simulated cable length / configured (L = 1.0 m)")
        ax.set_ylabel("simulated load mass / configured (m = 2.0 kg)")
        settled = sum(1 for u in unsettled if not u)
        ax.set_title(f"{controller}: {settled} of {len(cases)} runs settled")
        ax.legend(loc="upper right", fontsize=8)
        fig.tight_layout()
        path = os.path.join(args.out, f"sweep_{controller}.png")
        fig.savefig(path, dpi=110)
        plt.close(fig)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
