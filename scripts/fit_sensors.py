#!/usr/bin/env python3
"""Fits the simulated sensors' noise models to statistics of real depth frames
(results/sensors/README.md says where the frames come from and how to run it).

    /usr/bin/python3 scripts/fit_sensors.py SENSOR --data DIR [--posebench BIN]
        [--out results/sensors] [--quick]

SENSOR is astra (structured light) or kinect_one (time of flight). The real
frames are the entries of results/sensors/sources.json of that sensor's kind
(each names its repository, path and commit; the file itself is read from
DIR/<local>, never committed). Their statistics (scripts/sensor_stats.py)
are measured, then scenes are generated with the calibration config
(configs/calibration/SENSOR.yaml, `noise:` overridden) by `posebench
generate` and measured identically, and the model parameters are searched:
  structured light: disparity_step_px from the measured quantization steps
    (step = z^2 * disparity_step_px / (fx * baseline), so the step per z^2
    times the simulated sensor's fx * baseline); then disparity_sigma_px and
    smoothing_radius_px over a grid (coarse, then refined) minimizing the
    mean squared log ratio of simulated to real noise per depth bin; then
    max_incidence_deg over a grid minimizing the squared differences of the
    missing rate per incidence-angle bin.
  time of flight: sigma_base_mm and sigma_per_m2_mm scaled together by one
    factor (the literature's shape of the noise over depth kept: the real
    frames have enough planar patches only from 0.5 to 1.25 m to fix its
    level, not its growth), over a grid minimizing the noise loss above on
    the bins with at least TOF_MIN_PATCHES real patches; then
    flying_fraction and edge_filter_span_mm over a grid minimizing the
    squared differences of the flying (mixed-pixel) rate per depth bin,
    weighted by the real triplets of the bin (bins with at least
    TOF_MIN_TRIPLETS); then max_incidence_deg as for structured light.
    Without time-of-flight frames in sources.json, SENSOR's file records
    that it is not calibrated, with the simulated statistics of the model.
Frames of role holdout are not fitted to: their statistics are written
beside the fit's ("holdout") to check it on data it did not see.
Writes OUT/fit_SENSOR.json (provenance, real statistics, every evaluated
candidate, the fitted parameters, the simulated statistics before and after)
and OUT/fit_SENSOR.png. Deterministic: fixed scene seeds, no other
randomness. Needs numpy and matplotlib (Debian's python3-numpy,
python3-matplotlib: run it with /usr/bin/python3)."""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sensor_io  # noqa: E402
import sensor_stats  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
KIND = {"astra": "structured_light", "kinect_one": "time_of_flight"}
# The simulated profiles' intrinsics and baseline the disparity step is
# converted with (src/render/sensor.cpp: Intrinsics::from_fov(640, 480, 59, 46)).
ASTRA_FX = 320.0 / math.tan(math.radians(29.5))
ASTRA_BASELINE_MM = 75.0
# The models before the fit, given explicitly so that "before" does not depend
# on the defaults of the binary that runs the fit.
OLD_DEFAULTS = {
    "astra": {"model": "structured_light", "baseline_mm": 75.0, "disparity_step_px": 0.125,
              "disparity_sigma_px": 0.05, "smoothing_radius_px": 1, "smoothing_edge_px": 1.0,
              "max_incidence_deg": 75.0, "shadows": True},
    # the model before its fit: literature noise, every edge pixel mixed, the
    # driver's edge filter (results/sensors/README.md)
    "kinect_one": {"model": "tof", "sigma_base_mm": 1.5, "sigma_per_m2_mm": 0.75, "edge_jump_mm": 30.0,
                   "flying_fraction": 1.0, "max_incidence_deg": 80.0, "driver_edge_filter": True,
                   "edge_filter_close_mm": 50.0, "edge_filter_far_mm": 30.0, "edge_filter_span_mm": 100.0},
}
NOISE_BINS = (500.0, 4000.0)  # depth range the noise is fitted over
QUANT_MIN_Z = 1500.0          # below, the real sensor's 1 mm output rounding hides the step
TOF_MIN_PATCHES = 200         # time of flight: noise bins with fewer real patches are clutter, not planes
TOF_MIN_TRIPLETS = 100        # time of flight: flying-rate bins with fewer real edge triplets are left out


def load_sources(path, sensor):
    """The frames of SENSOR's kind that the fit uses (role full or geometry)
    and those it leaves out to check it against (role holdout)."""
    with open(path) as f:
        src = json.load(f)
    mine = [s for s in src["frames"] if s["kind"] == KIND[sensor]]
    return [s for s in mine if s.get("role") != "holdout"], [s for s in mine if s.get("role") == "holdout"]


def measure_real(sources, data_dir):
    stats = sensor_stats.Stats()
    for s in sources:
        path = os.path.join(data_dir, s["local"])
        print("real: %s  <- %s %s @ %s (%s)" % (s["local"], s["repo"], s["path"], s["commit"][:12], s["sensor"]))
        depth, K, lum = sensor_io.read_frame(path, s)
        stats.add(depth, K, luminance=lum, geometry_only=s.get("role") == "geometry")
    return stats


def noise_yaml(params):
    return "{" + ", ".join("%s: %s" % (k, json.dumps(v)) for k, v in params.items()) + "}"


def simulate(sensor, params, posebench, images, seed=None):
    """Stats of scenes generated with configs/calibration/SENSOR.yaml and noise `params`."""
    with open(os.path.join(ROOT, "configs", "calibration", sensor + ".yaml")) as f:
        text = f.read()
    tmp = tempfile.mkdtemp(prefix="fit_sensors_")
    try:
        cfg = os.path.join(tmp, sensor + ".yaml")
        with open(cfg, "w") as f:
            f.write(text + "\nregistry: %s\n" % os.path.join(ROOT, "models", "models.yaml"))
            if params:
                f.write("noise: %s\n" % noise_yaml(params))
        cmd = [posebench, "generate", cfg, "--out", os.path.join(tmp, "out"), "--images", str(images), "-q"]
        if seed is not None:
            cmd += ["--seed", str(seed)]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        scene = os.path.join(tmp, "out", "test", "000001")
        with open(os.path.join(scene, "scene_camera.json")) as f:
            ids = sorted(int(k) for k in json.load(f))
        stats = sensor_stats.Stats()
        for i in ids:
            depth, K = sensor_io.read_bop_depth(scene, i)
            stats.add(depth, K)
        return stats.summary()
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def noise_loss(sim, real):
    """Mean squared log ratio of the noise medians over the bins both have."""
    terms = []
    for (lo, hi), s, r in zip(real["bins_mm"], sim["noise_mm"]["median"], real["noise_mm"]["median"]):
        if s and r and lo >= NOISE_BINS[0] and hi <= NOISE_BINS[1]:
            terms.append(math.log(s / r) ** 2)
    return sum(terms) / len(terms) if terms else float("inf")


def incidence_loss(sim, real):
    """Sum of squared missing-rate differences over the angle bins both have."""
    a, b = sim["incidence"]["missing_rate"], real["incidence"]["missing_rate"]
    return sum((x - y) ** 2 for x, y in zip(a, b) if x is not None and y is not None)


def noise_loss_min_patches(sim, real, min_patches):
    """noise_loss over the bins with at least min_patches real patches."""
    kept = dict(real, noise_mm=dict(real["noise_mm"], median=[
        m if n >= min_patches else None for m, n in zip(real["noise_mm"]["median"], real["noise_mm"]["patches"])]))
    return noise_loss(sim, kept)


def flying_loss(sim, real, min_triplets):
    """Squared differences of the flying rate per depth bin, weighted by the
    real triplets, over the bins with at least min_triplets real triplets (a
    bin the simulation has no rate for counts as rate 0)."""
    num = den = 0.0
    for s, r, n in zip(sim["flying"]["rate"], real["flying"]["rate"], real["flying"]["triplets"]):
        if r is None or n < min_triplets:
            continue
        num += n * ((s or 0.0) - r) ** 2
        den += n
    return num / den if den else float("inf")


def quant_per_z2(summary):
    """Median over bins (centre z >= QUANT_MIN_Z) of step / z^2, in 1/mm."""
    vals = [q / ((lo + hi) / 2) ** 2 for (lo, hi), q in zip(summary["bins_mm"], summary["quant_step_mm"]["median"])
            if q and (lo + hi) / 2 >= QUANT_MIN_Z]
    return float(np.median(vals)) if vals else None


def search(label, candidates, evaluate, loss):
    """Evaluates every candidate; returns (best params, table of all)."""
    table = []
    for c in candidates:
        summary = evaluate(c)
        value = loss(summary)
        table.append({"params": c, "loss": round(value, 5)})
        print("%s %s loss %.5f" % (label, noise_yaml(c), value))
    best = min(table, key=lambda t: t["loss"])
    return dict(best["params"]), table


def fit_astra(real, posebench, quick):
    images = 6 if quick else 12
    q = quant_per_z2(real)
    step = round(q * ASTRA_FX * ASTRA_BASELINE_MM, 4)
    print("real quantization: step = %.3g z^2 /mm -> disparity_step_px %.4f" % (q, step))
    base = dict(OLD_DEFAULTS["astra"], disparity_step_px=step)
    evaluate = lambda c: simulate("astra", dict(base, **c), posebench, images)  # noqa: E731
    coarse = [{"disparity_sigma_px": s, "smoothing_radius_px": r}
              for r in (0, 1, 2, 3)
              for s in ((0.1, 0.2, 0.3) if quick else (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6))]
    best, table = search("noise", coarse, evaluate, lambda s: noise_loss(s, real))
    s0 = best["disparity_sigma_px"]
    fine = [{"disparity_sigma_px": round(s0 + d, 4), "smoothing_radius_px": best["smoothing_radius_px"]}
            for d in (-0.03, -0.015, 0.015, 0.03) if s0 + d > 0]
    best2, table2 = search("noise", fine, evaluate, lambda s: noise_loss(s, real))
    table += table2
    if min(t["loss"] for t in table2) < min(t["loss"] for t in table if t not in table2):
        best = best2
    angles = [{"max_incidence_deg": a} for a in ((75, 85, 90) if quick else (75, 78, 80, 82, 84, 86, 88, 90))]
    best_a, table_a = search("incidence", angles, lambda c: evaluate(dict(best, **c)),
                             lambda s: incidence_loss(s, real))
    fitted = dict(base, **best, **best_a)
    return fitted, {"quant_step_per_z2_per_mm": q, "noise_search": table, "incidence_search": table_a}


def fit_tof(real, posebench, quick):
    images = 6 if quick else 12
    base = dict(OLD_DEFAULTS["kinect_one"])
    evaluate = lambda c: simulate("kinect_one", dict(base, **c), posebench, images)  # noqa: E731
    scales = (0.5, 0.75, 1.0) if quick else (0.4, 0.5, 0.55, 0.6, 0.65, 0.7, 0.8, 0.9, 1.0, 1.2)
    noise = [{"sigma_base_mm": round(base["sigma_base_mm"] * k, 4),
              "sigma_per_m2_mm": round(base["sigma_per_m2_mm"] * k, 4)} for k in scales]
    best, table = search("noise", noise, evaluate, lambda s: noise_loss_min_patches(s, real, TOF_MIN_PATCHES))
    edges = [{"flying_fraction": f, "edge_filter_span_mm": span}
             for f in ((0.5, 1.0) if quick else (0.25, 0.5, 0.75, 1.0))
             for span in ((100.0, 200.0) if quick else (100.0, 150.0, 200.0, 300.0))]
    best_e, table_e = search("edges", edges, lambda c: evaluate(dict(best, **c)),
                             lambda s: flying_loss(s, real, TOF_MIN_TRIPLETS))
    angles = [{"max_incidence_deg": a} for a in ((75, 85, 90) if quick else (75, 78, 80, 82, 84, 86, 88, 90))]
    best_a, table_a = search("incidence", angles, lambda c: evaluate(dict(best, **best_e, **c)),
                             lambda s: incidence_loss(s, real))
    fitted = dict(base, **best, **best_e, **best_a)
    return fitted, {"noise_search": table, "edge_search": table_e, "incidence_search": table_a}


def plot(path, title, series, flying=False):
    """Noise, quantization (flying: the mixed-pixel rate at edges instead),
    missing per depth and missing per incidence angle of each (summary,
    label, colour, marker) in `series`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 2, figsize=(11, 8))
    z = [(lo + hi) / 2 for lo, hi in series[0][0]["bins_mm"]]
    panels = [(ax[0, 0], lambda s: s["noise_mm"]["median"], "noise: plane-fit residual RMS (mm)", True),
              (ax[0, 1], lambda s: s["flying"]["rate"], "flying (mixed) pixels among edge triplets", False)
              if flying else
              (ax[0, 1], lambda s: s["quant_step_mm"]["median"], "quantization step (mm)", True),
              (ax[1, 0], lambda s: s["missing"]["rate"], "missing fraction (8x8 blocks)", False)]
    for a, get, ylabel, log in panels:
        for s, label, color, marker in series:
            pts = [(x, y) for x, y in zip(z, get(s)) if y is not None]
            if pts:
                a.plot(*zip(*pts), marker=marker, color=color, label=label)
        a.set_xlabel("depth (mm)")
        a.set_ylabel(ylabel)
        if log:
            a.set_yscale("log")
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8)
    angles = series[0][0]["incidence"]["bins_deg"]
    centres = [(a0 + a1) / 2 for a0, a1 in zip(angles[:-1], angles[1:])]
    for s, label, color, marker in series:
        pts = [(x, y) for x, y in zip(centres, s["incidence"]["missing_rate"]) if y is not None]
        if pts:
            ax[1, 1].plot(*zip(*pts), marker=marker, color=color, label=label)
    ax[1, 1].set_xlabel("incidence angle (deg)")
    ax[1, 1].set_ylabel("missing fraction of planar blocks")
    ax[1, 1].grid(True, alpha=0.3)
    ax[1, 1].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sensor", choices=sorted(KIND))
    ap.add_argument("--data", required=True, help="folder holding the real frames (sources.json 'local' names)")
    ap.add_argument("--sources", default=os.path.join(ROOT, "results", "sensors", "sources.json"))
    ap.add_argument("--posebench", default=os.path.join(ROOT, "build", "posebench"))
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "sensors"))
    ap.add_argument("--quick", action="store_true", help="fewer images and candidates (a smoke run)")
    args = ap.parse_args(argv)
    sources, holdout = load_sources(args.sources, args.sensor)
    report = {"sensor": args.sensor, "kind": KIND[args.sensor], "sources": sources,
              "measurement": {k: getattr(sensor_stats, k) for k in
                              ("P", "JUMP_REL", "JUMP_MM", "B", "EDGE_R", "EDGE_REL", "EDGE_MM", "MIN_LEVELS")}}
    final_images, final_seed = (8, 4242) if args.quick else (24, 4242)
    report["old_defaults"] = OLD_DEFAULTS[args.sensor]
    before = simulate(args.sensor, OLD_DEFAULTS[args.sensor], args.posebench, final_images, final_seed)
    before_label = "old defaults" if sources else "current (uncalibrated) defaults"
    report["simulated_" + before_label.split(" (")[0].replace(" ", "_")] = before
    real = None
    if not sources:
        report["status"] = ("not calibrated: no real %s depth frames were found (see README.md); the model "
                            "keeps its literature defaults" % KIND[args.sensor].replace("_", "-"))
        print(report["status"])
    else:
        real_stats = measure_real(sources, args.data)
        real = real_stats.summary()
        report["real"] = real
        fit = fit_astra if args.sensor == "astra" else fit_tof
        fitted, search_log = fit(real, args.posebench, args.quick)
        report["status"] = "calibrated"
        report["fitted_noise"] = fitted
        report["search"] = search_log
        report["simulated_fitted"] = simulate(args.sensor, fitted, args.posebench, final_images, final_seed)
        after = report["simulated_fitted"]
        report["loss"] = {"noise_old": noise_loss(before, real), "noise_fitted": noise_loss(after, real),
                          "incidence_old": incidence_loss(before, real),
                          "incidence_fitted": incidence_loss(after, real)}
        if args.sensor == "kinect_one":
            report["loss"].update({
                "noise_fitted_bins_old": noise_loss_min_patches(before, real, TOF_MIN_PATCHES),
                "noise_fitted_bins_fitted": noise_loss_min_patches(after, real, TOF_MIN_PATCHES),
                "flying_old": flying_loss(before, real, TOF_MIN_TRIPLETS),
                "flying_fitted": flying_loss(after, real, TOF_MIN_TRIPLETS)})
        print("fitted: %s" % noise_yaml(fitted))
        if holdout:  # frames the fit did not see: their statistics beside the fit's
            report["holdout"] = measure_real(holdout, args.data).summary()
    os.makedirs(args.out, exist_ok=True)
    out = os.path.join(args.out, "fit_%s.json" % args.sensor)
    with open(out, "w") as f:
        json.dump(report, f, indent=1)
        f.write("\n")
    series = [(real, "real", "k", "o")] if real else []
    if report.get("holdout"):
        series.append((report["holdout"], "real, held out (not fitted)", "0.55", "D"))
    series.append((before, "simulated, " + before_label, "tab:red", "x"))
    if real:
        series.append((report["simulated_fitted"], "simulated, fitted", "tab:blue", "s"))
    plot(os.path.join(args.out, "fit_%s.png" % args.sensor), "%s: real vs simulated depth statistics" % args.sensor,
         series, flying=args.sensor == "kinect_one")
    print("wrote " + out)


if __name__ == "__main__":
    main()
