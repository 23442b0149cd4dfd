#!/usr/bin/python3
"""Draws the map written by crane_filter_delay_map: plot_filter_delay_map.py JSON PNG.

One panel per anti-swing law: the dominant-pair damping ratio against the estimator's cut-off
frequency (log axis), one line per cable length, the law's unfiltered damping dashed, unstable
points marked, the stack's cut-off as a vertical line; a last panel with the swing-rate noise the
filter leaves (the price of a higher cut-off).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(argv):
    if len(argv) != 3:
        print("usage: plot_filter_delay_map.py JSON PNG", file=sys.stderr)
        return 2
    with open(argv[1], encoding="utf-8") as handle:
        data = json.load(handle)
    cutoffs = np.asarray(data["cutoffs_hz"], dtype=float)
    cables = data["cable_lengths_m"]
    laws = data["laws"]
    fig, axes = plt.subplots(1, len(laws) + 1, figsize=(4.2 * (len(laws) + 1), 4.2))
    for ax, law in zip(axes, laws):
        for j, length in enumerate(cables):
            damping = np.array([np.nan if v is None else v for v in law["damping"][j]], dtype=float)
            stable = np.asarray(law["stable"][j], dtype=bool)
            line, = ax.semilogx(cutoffs, damping, marker="o", markersize=3, label=f"L = {length:g} m")
            ax.semilogx(cutoffs[~stable], damping[~stable], "x", color=line.get_color(), markersize=8)
        ax.axhline(law["unfiltered_damping"], color="gray", linestyle="--", label="no filter")
        ax.axhline(0.0, color="black", linewidth=0.5)
        ax.axvline(data["stack_cutoff_hz"], color="red", linestyle=":", label="the stack's cut-off")
        ax.set_title(law["name"])
        ax.set_xlabel("cut-off frequency f_c [Hz]")
        ax.set_ylabel("damping ratio of the dominant pair")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    noise = data["noise"]
    ax = axes[-1]
    ax.loglog([n["cutoff_hz"] for n in noise], [n["swing_rate_rms_deg_s"] for n in noise], marker="o", label="swing rate [deg/s]")
    ax.loglog([n["cutoff_hz"] for n in noise], [n["swing_rms_deg"] for n in noise], marker="s", label="swing [deg]")
    ax.axvline(data["stack_cutoff_hz"], color="red", linestyle=":")
    ax.set_title("encoder noise left by the filter")
    ax.set_xlabel("cut-off frequency f_c [Hz]")
    ax.set_ylabel("RMS")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.suptitle("Filter delay vs anti-swing damping (section 5.1), x = unstable")
    fig.tight_layout()
    fig.savefig(argv[2], dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
