#!/usr/bin/env python3
"""Plots of `posebench sensor-fit`'s statistics: sensor_fit.json -> OUT/sensor_fit.png.

Eight panels, real frames against their twins with the base profile's noise
and with the fitted noise: spread and bias of the depth residual per true
depth, the quantization step, the normals' error, missing rate per incidence
angle, per distance to the object's outline and per object, and what the
measured depth is across the outline.
Each real bin is labelled with its pixel count n (frames for the steps).
"""
import json
import os
import sys

SETS = [("real", "real", "k", "o", "-"),
        ("simulated_base", "base profile", "tab:blue", "s", "--"),
        ("simulated_fitted", "fitted", "tab:red", "^", ":")]


def mid(b):
    hi = b["hi"] if b["hi"] is not None else b["lo"] + 1
    return 0.5 * (b["lo"] + hi) if hi != b["lo"] else b["lo"]


def geometric_missing(b):
    n = b["n"] - b["nearer"]
    return b["missing"] / n if n > 0 else float("nan")


def series(stats, key, value, min_n=100):
    xs, ys, ns = [], [], []
    for b in stats[key]:
        if b["n"] < min_n:
            continue
        xs.append(mid(b))
        ys.append(value(b))
        ns.append(b["n"])
    return xs, ys, ns


def label_n(ax, xs, ys, ns):
    for x, y, n in zip(xs, ys, ns):
        ax.annotate(f"n={n}", (x, y), textcoords="offset points", xytext=(0, 6), fontsize=6, ha="center")


def panel(ax, data, key, value, title, xlabel, ylabel, min_n=100):
    for name, label, colour, marker, style in SETS:
        if name not in data:
            continue
        xs, ys, ns = series(data[name], key, value, min_n)
        ax.plot(xs, ys, color=colour, marker=marker, linestyle=style, label=label, markersize=4)
        if name == "real":
            label_n(ax, xs, ys, ns)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel(xlabel, fontsize=8)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)


def silhouette(ax, data):
    for name, label, colour, marker, style in SETS:
        if name not in data:
            continue
        bins = [b for b in data[name]["silhouette"] if b["n"] > 0]
        xs = [b["d"] for b in bins]
        ax.plot(xs, [b["object"] / b["n"] for b in bins], color=colour, marker=marker, linestyle=style,
                label=f"{label}: like the object", markersize=4)
        ax.plot(xs, [b["missing"] / b["n"] for b in bins], color=colour, marker="x", linestyle=style,
                alpha=0.6, label=f"{label}: missing", markersize=4)
        if name == "real":
            label_n(ax, xs, [b["object"] / b["n"] for b in bins], [b["n"] for b in bins])
    ax.axvline(0.5, color="grey", linewidth=0.8)
    ax.set_title("across the outline (inside <= 0 < outside)", fontsize=9)
    ax.set_xlabel("signed distance to the rendered outline (px)", fontsize=8)
    ax.set_ylabel("fraction of pixels", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6)


def quantization(ax, data):
    for name, label, colour, marker, style in SETS:
        if name not in data:
            continue
        q = data[name]["quantization"]
        xs = [0.5 * (b["lo"] + b["hi"]) for b in q]
        ys = [b["step_mm"] for b in q]
        ax.plot(xs, ys, color=colour, marker=marker, linestyle=style, label=label, markersize=4)
        if name == "real":
            for x, y, b in zip(xs, ys, q):
                ax.annotate(f"{b['frames']} fr", (x, y), textcoords="offset points", xytext=(0, 6), fontsize=6,
                            ha="center")
    ax.set_title("depth quantization step", fontsize=9)
    ax.set_xlabel("depth (mm)", fontsize=8)
    ax.set_ylabel("median step between distinct depths (mm)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)


def normals(ax, data):
    for name, label, colour, marker, style in SETS:
        if name not in data or not data[name].get("normal_error"):
            continue
        bins = data[name]["normal_error"]
        xs = [0.5 * (b["lo"] + b["hi"]) for b in bins]
        ys = [b["median_deg"] for b in bins]
        ax.plot(xs, ys, color=colour, marker=marker, linestyle=style, label=label, markersize=4)
        if name == "real":
            label_n(ax, xs, ys, [b["n"] for b in bins])
    ax.set_title("normal error (plane over 11 x 11 px)", fontsize=9)
    ax.set_xlabel("true depth (mm)", fontsize=8)
    ax.set_ylabel("median angle to the true normal (deg)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)


def per_object(ax, data):
    ids = sorted(data["real"]["by_object"], key=int)
    width = 0.27
    for k, (name, label, colour, _, _) in enumerate(SETS):
        if name not in data:
            continue
        objs = data[name]["by_object"]
        xs = [i + (k - 1) * width for i in range(len(ids))]
        ax.bar(xs, [objs[o]["missing_rate"] if o in objs else 0 for o in ids], width, color=colour, label=label)
    ax.set_xticks(range(len(ids)))
    ax.set_xticklabels([f"{o}\nn={data['real']['by_object'][o]['n']}" for o in ids], fontsize=5)
    ax.set_title("missing data per object (obj_id, real pixels)", fontsize=9)
    ax.set_ylabel("missing rate", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3, axis="y")


def main(argv):
    if len(argv) != 3:
        print("usage: sensor_fit_plot.py SENSOR_FIT.json OUT_DIR", file=sys.stderr)
        return 2
    with open(argv[1]) as f:
        data = json.load(f)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(argv[2], exist_ok=True)
    fig, axes = plt.subplots(2, 4, figsize=(20, 8.5))
    panel(axes[0][0], data, "by_depth", lambda b: b["spread_mm"], "depth noise (robust spread)",
          "true depth (mm)", "1.4826 MAD of residual (mm)")
    axes[0][0].legend(fontsize=7)
    panel(axes[0][1], data, "by_depth", lambda b: b["bias_mm"], "depth bias", "true depth (mm)",
          "median residual, measured - true (mm)")
    quantization(axes[0][2], data)
    panel(axes[1][0], data, "by_incidence", geometric_missing, "missing data by incidence angle",
          "angle between ray and normal (deg)", "missing rate")
    panel(axes[1][1], data, "by_edge_px", geometric_missing, "missing data by distance to the outline",
          "distance inside the outline (px; last bin: and more)", "missing rate")
    silhouette(axes[1][2], data)
    normals(axes[0][3], data)
    per_object(axes[1][3], data)
    loss = data.get("loss", {})
    fig.suptitle(f"{data.get('dataset', '')}: {data.get('images', 0)} real images; loss base "
                 f"{loss.get('base', {}).get('total', float('nan')):.3f}, fitted "
                 f"{loss.get('fitted', {}).get('total', float('nan')):.3f}", fontsize=10)
    fig.tight_layout()
    out = os.path.join(argv[2], "sensor_fit.png")
    fig.savefig(out, dpi=110)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
