#!/usr/bin/python3
"""Draws a damping map written by crane_damping_map: plot_damping_map.py JSON PNG.

Heat map of the dominant-pair damping ratio over the two parameters, unstable points masked
(white), with contour lines and the maximum marked.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(argv):
    if len(argv) != 3:
        print("usage: plot_damping_map.py JSON PNG", file=sys.stderr)
        return 2
    with open(argv[1], encoding="utf-8") as handle:
        data = json.load(handle)
    first, second = data["parameters"]
    x = np.asarray(first["values"], dtype=float)
    y = np.asarray(second["values"], dtype=float)
    values = np.array([[np.nan if v is None else v for v in row] for row in data["values"]], dtype=float)
    stable = np.asarray(data["stable"], dtype=bool)
    values[~stable] = np.nan
    z = values.T  # rows: second parameter
    fig, ax = plt.subplots(figsize=(7, 5))
    mesh = ax.pcolormesh(x, y, np.ma.masked_invalid(z), shading="auto", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="damping ratio of the dominant pair")
    finite = np.isfinite(z)
    if finite.sum() > 4:
        levels = [l for l in (0.05, 0.1, 0.2, 0.3, 0.4) if l < np.nanmax(z)]
        if levels:
            contour = ax.contour(x, y, np.where(finite, z, -1.0), levels=levels, colors="w", linewidths=0.7)
            ax.clabel(contour, fmt="%.2f", fontsize=7)
    at = data["at"]
    ax.plot(at[first["name"]], at[second["name"]], "r*", markersize=14,
            label="max %.3f at (%.3g, %.3g)" % (data["max_damping"], at[first["name"]], at[second["name"]]))
    ax.set_xlabel(first["name"])
    ax.set_ylabel(second["name"])
    ax.set_title("%s damping map (unstable: blank)" % data["controller"])
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
