#!/usr/bin/python3
"""Draws frequency responses written by crane_frequency_response: plot_frequency_response.py JSON PNG.

Like figure 4.5 of Omar (2003): top, magnitude of each differentiator relative to the ideal s
(|H| / 2 pi f, 1 = ideal); bottom, phase in degrees (ideal +90). Both on a log frequency axis.
The cascade Butterworth low-pass + (4.10), which the estimator actually runs, is dashed.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def values(sequence):
    return np.array([np.nan if v is None else v for v in sequence], dtype=float)


def main(argv):
    if len(argv) != 3:
        print("usage: plot_frequency_response.py JSON PNG", file=sys.stderr)
        return 2
    with open(argv[1], encoding="utf-8") as handle:
        data = json.load(handle)
    f = np.asarray(data["frequency_hz"], dtype=float)
    fs = data["sample_rate_hz"]
    fc = data["cutoff_hz"]

    fig, (ax_mag, ax_phase) = plt.subplots(2, 1, figsize=(8, 7.5), sharex=True)
    ax_mag.semilogx(f, np.ones_like(f), color="black", linewidth=1.8, label="ideal s")
    ax_phase.semilogx(f, np.full_like(f, data["ideal"]["phase_deg"]), color="black", linewidth=1.8,
                      label="ideal s")
    styles = {
        "backward": ("tab:blue", (0, (5, 3))),
        "al_alaoui_first_order": ("tab:orange", "-."),
        "al_alaoui_second_order": ("tab:green", ":"),
    }
    for key, (color, style) in styles.items():
        response = data["differentiators"][key]
        ax_mag.semilogx(f, values(response["magnitude_ratio"]), color=color, linestyle=style, linewidth=1.6,
                        label=response["label"])
        ax_phase.semilogx(f, values(response["phase_deg"]), color=color, linestyle=style, linewidth=1.6,
                          label=response["label"])
    cascade = data["cascade"]
    ax_mag.semilogx(f, values(cascade["magnitude_ratio"]), color="tab:red", linestyle="--", linewidth=1.6,
                    label=f"{cascade['label']} (fc = {fc:g} Hz)")
    ax_phase.semilogx(f, values(cascade["phase_deg"]), color="tab:red", linestyle="--", linewidth=1.6,
                      label=f"{cascade['label']} (fc = {fc:g} Hz)")

    for ax in (ax_mag, ax_phase):
        ax.axvline(fc, color="grey", linewidth=0.8, linestyle=":")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlim(f[0], f[-1])
    ax_mag.set_ylabel("|H| / |ideal|  (|ideal| = 2 pi f)")
    ax_mag.set_ylim(0.0, 1.3)
    ax_mag.set_title(f"Differentiators (4.8)-(4.10) vs ideal, fs = {fs:g} Hz (Omar 2003, fig. 4.5)")
    ax_mag.legend(loc="lower left", fontsize=8)
    ax_phase.set_ylabel("phase [deg]")
    ax_phase.set_xlabel("frequency [Hz]")
    ax_phase.set_yticks(np.arange(-270, 91, 45))
    fig.tight_layout()
    fig.savefig(argv[2], dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
