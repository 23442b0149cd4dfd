#!/usr/bin/python3
"""Draws one PNG per maneuver of a crane_demo run: positions, swing angles and drive voltages
against time, with the reference, friction compensation on (solid) and off (dashed).

Usage: plot_maneuvers.py --out DIR   (reads DIR/summary.json and the CSV files it names)
"""
import argparse
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


CONTROLLER_TITLES = {
    "gain_scheduling_partial": "gain-scheduling partial state feedback (3.19)",
    "gain_scheduling_full": "gain-scheduling full state feedback (3.26)",
    "pd": "PD anti-swing (3.45) + PD tracking",
    "delay1": "delayed-feedback anti-swing (3.47) + PD tracking",
    "delay2": "delayed-feedback reference correction (3.50) + PD tracking",
    "fuzzy": "fuzzy anti-swing + PD tracking",
}


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{path}: no rows")
    return {key: [float(r[key]) for r in rows] for key in rows[0].keys()}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", required=True, help="demo output directory")
    args = parser.parse_args()
    with open(os.path.join(args.out, "summary.json")) as f:
        summary = json.load(f)
    controller_title = CONTROLLER_TITLES.get(summary.get("controller", "delay1"), summary.get("controller", "delay1"))
    by_name = {}
    for m in summary["maneuvers"]:
        by_name.setdefault(m["name"], []).append(m)
    deg = 180.0 / math.pi
    for name, runs in by_name.items():
        fig, axes = plt.subplots(5, 1, figsize=(9, 13), sharex=True)
        for run in sorted(runs, key=lambda r: not r["friction_compensation"]):
            d = read_csv(os.path.join(args.out, run["csv"]))
            on = run["friction_compensation"]
            style = "-" if on else "--"
            label = "compensation on" if on else "compensation off"
            t = d["t"]
            axes[0].plot(t, d["x"], style, label=f"x, {label}")
            # An overhead crane's CSV carries the bridge (y, u_y, y_ref): drawn where a tower crane's slew is.
            bridge = "y" in d
            bridge_drawn = bridge
            if bridge:
                axes[1].plot(t, d["y"], style, label=f"y, {label}")
                axes[4].plot(t, d["u_y"], style, label=f"bridge, {label}")
            else:
                axes[1].plot(t, [g * deg for g in d["gamma"]], style, label=f"gamma, {label}")
                axes[4].plot(t, d["u_gamma"], style, label=f"slew, {label}")
            axes[2].plot(t, [p * deg for p in d["phi"]], style, label=f"phi (in-plane), {label}")
            axes[2].plot(t, [p * deg for p in d["theta"]], style, label=f"theta (out-of-plane), {label}")
            axes[3].plot(t, d["u_x"], style, label=f"trolley, {label}")
            if on:
                axes[0].plot(t, d["x_ref"], ":", color="k", label="reference")
                if bridge:
                    axes[1].plot(t, d["y_ref"], ":", color="k", label="reference")
                else:
                    axes[1].plot(t, [g * deg for g in d["gamma_ref"]], ":", color="k", label="reference")
        axes[0].set_ylabel("trolley x [m]")
        axes[1].set_ylabel("bridge y [m]" if bridge_drawn else "slew gamma [deg]")
        axes[2].set_ylabel("swing [deg]")
        axes[3].set_ylabel("trolley drive [V]")
        axes[4].set_ylabel("bridge drive [V]" if bridge_drawn else "slew drive [V]")
        axes[4].set_xlabel("time since the move started [s]")
        for ax in axes:
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7, loc="best")
        fig.suptitle(f"maneuver '{name}': {controller_title}, simulated plant over DDS")
        fig.tight_layout()
        path = os.path.join(args.out, f"{name}.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        print(f"plot: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
