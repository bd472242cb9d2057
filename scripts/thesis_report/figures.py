"""The README's figures: merged plots (scripts/plot.py) and their series as tables."""
import json
import os
import subprocess

from .formatting import pct

SCRIPTS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


PLOT_PYTHON = "/usr/bin/python3"  # with Debian's python3-matplotlib, for scripts/plot.py


def merged_plot(res, name, parts, title):
    """One plot of several experiments' series (OUT/plots/NAME.png), or None."""
    series, xl = [], None
    for p in parts:
        for pl in res[p].plots:
            family = p.split("_")[-1]  # fig_4_7_global -> global: a line style per family (plot.py)
            series += [dict(s, family=family, label="%s, %s" % (s.get("method", s["label"]), family))
                       for s in pl["series"]]
            xl = pl["x_label"]
    if not series:
        return None
    path = os.path.join(res.raw, name + ".plots.json")
    with open(path, "w") as f:
        json.dump([{"name": name, "x_label": xl, "title": title, "series": series}], f)
    plot_py = os.path.join(SCRIPTS, "plot.py")
    subprocess.run([PLOT_PYTHON, plot_py, path, res.plots], check=True, capture_output=True)
    return name + ".png"


def series_rows(plots):
    """Plots' series with one x axis as a table: robustness (/ mean time) per x value."""
    xs = sorted({x for pl in plots for s in pl["series"] for x in s["x"]})
    o = ["| %s | " % plots[0]["x_label"] + " | ".join("%g" % x for x in xs) + " |", "|---|" + "---|" * len(xs)]
    for s in (s for pl in plots for s in pl["series"]):
        rob, tm = dict(zip(s["x"], s["robustness"])), dict(zip(s["x"], s["time"]))
        o.append("| %s | " % s["label"] + " | ".join(
            ("%s / %.1fs" % (pct(rob[x]), tm[x]) if tm.get(x) is not None else pct(rob[x])) if x in rob else "-"
            for x in xs) + " |")
    return o + [""]


def series_table(res, parts):
    """One table per x axis over the plots of the experiments `parts`."""
    by_axis = {}
    for pl in (pl for p in parts if p in res for pl in res[p].plots):
        by_axis.setdefault(pl["x_label"], []).append(pl)
    return "\n".join(line for plots in by_axis.values() for line in series_rows(plots))


FIGS = [("fig_4_6", ["fig_4_6"], "Figure 4.6: LS5, CVFH and CESF, CRH skipped: robustness and time vs hypotheses",
         "The thesis pooled the occluded and non-occluded real-sensor scenes and left ESF out; here the non-occluded "
         "Astra and Kinect One sets."),
        ("fig_4_7", ["fig_4_7_global", "fig_4_7_local"], "Figure 4.7: LS5 robustness vs added noise",
         "The global descriptors use the thesis's one side view (0 degrees), which matches poorly in the table "
         "scenes seen from 30-70 degrees above. The thesis's claims on noise: conclusions C6 and C7."),
        ("fig_4_11", ["fig_4_11_global", "fig_4_11_local"], "Figure 4.11: statue robustness vs added noise",
         "The statue's table scenes (5 mm voxels) get much slower with noise: more voxels, keypoints and "
         "descriptors."),
        ("fig_4_12", ["fig_4_12"], "Figure 4.12: registration robustness vs added noise",
         "Registration starts from the ground truth perturbed as in Table 4.9, not from recognition hypotheses.")]


def figure_section(res, name, have, title, note):
    png = merged_plot(res, name, have, title) if len(have) > 1 else None
    if png is None:
        pl = res[have[0]].plots
        png = "%s_%s.png" % (have[0], pl[0]["name"]) if pl else None
    return ["### %s" % title,
            "Command: `scripts/thesis.sh --only %s`; %s: %s. %s%s\n" % (
                ",".join(have), "config" if len(have) == 1 else "configs",
                ", ".join("`configs/thesis/%s.yaml`" % p for p in have), note,
                " ![%s](plots/%s)" % (title, png) if png else ""),
            series_table(res, have)]


def section_figures(res):
    o = ["## Figures\n", "Cells: robustness / mean online time per image, per series (method and scene set) "
         "and x value; the thesis printed no numbers for its figures.\n"]
    for name, parts, title, note in FIGS:
        have = [p for p in parts if p in res]
        if have:
            o += figure_section(res, name, have, title, note)
    return o
