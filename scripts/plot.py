#!/usr/bin/env python3
"""Plots written by `posebench report --plots`: robustness (and time) against
a swept variable (noise sigma, number of hypotheses), one line per method and
scene set, as the thesis's Figures 4.6, 4.7, 4.11 and 4.12."""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(data_path, out_dir):
    with open(data_path) as f:
        plots = json.load(f)
    os.makedirs(out_dir, exist_ok=True)
    for p in plots:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        for s in p.get("series", []):
            xs = s["x"]
            axes[0].plot(xs, [None if v is None else 100 * v for v in s["robustness"]], marker="o", label=s["label"])
            axes[1].plot(xs, s["time"], marker="o", label=s["label"])
        axes[0].set_ylabel("robustness (% correct)")
        axes[0].set_ylim(-2, 102)
        axes[1].set_ylabel("mean time per image (s)")
        for ax in axes:
            ax.set_xlabel(p["x_label"])
            ax.grid(True, alpha=0.3)
        axes[0].legend(fontsize=7)
        fig.suptitle(p.get("title", ""))
        fig.tight_layout()
        out = os.path.join(out_dir, p["name"] + ".png")
        fig.savefig(out, dpi=110)
        plt.close(fig)
        print(out)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: plot.py PLOTS.json OUT_DIR")
    main(sys.argv[1], sys.argv[2])
