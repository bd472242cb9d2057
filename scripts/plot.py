#!/usr/bin/env python3
"""Plots written by `posebench report --plots`: robustness and time against
a swept variable (noise sigma, number of hypotheses), one line per method and
scene set, as the thesis's Figures 4.6, 4.7, 4.11 and 4.12.

Robustness is drawn with its 95% Wilson interval as a band and the number of
trials per point stated; a marker and colour per method and a line style per
scene set tell the series apart, or, when the series name a family (global /
local descriptors, as the thesis's Figures 4.7 and 4.11), a line style per
family and one row of panels per scene set; the time axis is logarithmic
when the times span more than a decade."""
import json
import os
import sys

from thesis_stats import wilson  # the 95% band, as the tables' intervals

LINE_STYLES = ["-", "--", ":", "-."]
MARKERS = ["o", "s", "^", "D", "v", "P", "X", "*", "<", ">"]


def styles(series):
    """Per series (in order) its (line style, marker, colour index): a line
    style per family ("global" / "local", when the series name one) or else
    per scene set, a marker and colour per method, in first-seen order."""
    groups, methods, out = [], [], []
    for s in series:
        g, m = s.get("family", s.get("scene", "")), s.get("method", s.get("label", ""))
        if g not in groups:
            groups.append(g)
        if m not in methods:
            methods.append(m)
        i, j = groups.index(g), methods.index(m)
        out.append((LINE_STYLES[i % len(LINE_STYLES)], MARKERS[j % len(MARKERS)], j))
    return out


def panels(series):
    """[(scene set or "", its series)]: one row of panels per scene set when
    the series name families (line styles then tell the families apart), else
    one row of everything."""
    if not any("family" in s for s in series):
        return [("", series)]
    scenes = []
    for s in series:
        if s.get("scene", "") not in scenes:
            scenes.append(s.get("scene", ""))
    return [(sc, [s for s in series if s.get("scene", "") == sc]) for sc in scenes]


def log_time_axis(series):
    """True when the positive mean times span more than a factor of 10."""
    ts = [t for s in series for t in s.get("time", []) if t is not None and t > 0]
    return len(ts) > 1 and max(ts) / min(ts) > 10


def trials_note(series):
    """'n = N trials per point' when every point has N trials, else a range."""
    ns = sorted({n for s in series for n in s.get("trials", [])})
    if not ns:
        return ""
    return "n = %d trials per point" % ns[0] if len(ns) == 1 else "n = %d to %d trials per point" % (ns[0], ns[-1])


def draw(p, out_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    series = p.get("series", [])
    rows = panels(series)
    fig, grid = plt.subplots(len(rows), 2, figsize=(12, 4.6 * len(rows)), squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    style = dict(zip(map(id, series), styles(series)))  # one style per series across the rows
    log_time = log_time_axis(series)
    for (scene, part), axes in zip(rows, grid):
        for s in part:
            ls, mk, ci = style[id(s)]
            c = colours[ci % len(colours)]
            xs = s["x"]
            rob = [None if v is None else 100 * v for v in s["robustness"]]
            axes[0].plot(xs, rob, linestyle=ls, marker=mk, color=c, label=s["label"])
            if s.get("trials"):
                band = [wilson(k, n) for k, n in zip(s["correct"], s["trials"])]
                axes[0].fill_between(xs, [100 * b[0] for b in band], [100 * b[1] for b in band], color=c,
                                     alpha=0.12)
            axes[1].plot(xs, s["time"], linestyle=ls, marker=mk, color=c, label=s["label"])
        axes[0].set_ylabel("robustness (% of trials correct; band: 95% interval)")
        axes[0].set_ylim(-2, 102)
        axes[1].set_ylabel("mean time per image (s)")
        if log_time:
            axes[1].set_yscale("log")
        for ax in axes:
            ax.set_xlabel(p["x_label"])
            ax.grid(True, alpha=0.3)
            if scene:
                ax.set_title(scene, fontsize=10)
        axes[0].legend(fontsize=7, title=trials_note(part) or None, title_fontsize=7)
    fig.suptitle(p.get("title", ""))
    fig.tight_layout()
    fig.savefig(out_path, dpi=110)
    plt.close(fig)


def main(data_path, out_dir):
    with open(data_path) as f:
        plots = json.load(f)
    os.makedirs(out_dir, exist_ok=True)
    for p in plots:
        out = os.path.join(out_dir, p["name"] + ".png")
        draw(p, out)
        print(out)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: plot.py PLOTS.json OUT_DIR")
    main(sys.argv[1], sys.argv[2])
