#!/usr/bin/env python3
"""Where recognition fails, stage by stage: the tables of results/real_recognition.

    scripts/real_diagnosis.py stages RUN [--variant LABEL=RUN ...] [--scenes S ...]
    scripts/real_diagnosis.py oracle --dataset DIR --method M [--posebench BIN]
                                     [--config YAML] [--cache DIR] [--targets FILE]
    scripts/real_diagnosis.py ar RUN --dataset SCENE=DIR ... [--posebench BIN]

`stages` reads the records of a `posebench run` (records.jsonl) and counts,
per scene and method, what became of each target:
  found       the estimate's MSSD is below 0.2 of the object's diameter;
  hypothesis  a correct hypothesis was among the ranked ones (`correct_rank`
              >= 0, the thesis's judgement: 50 mm and 1-|p.q| < 0.05);
  chosen      ... and verification ranked it first (`correct_rank` == 0);
  near        not found, but within 0.25 diameters of the ground truth (the
              right place, a wrong rotation: a flip of a box or a can);
  elsewhere   not found, more than a diameter away (another object, the
              table, the background);
  none        no hypothesis was accepted;
and the median seconds of recognition per target (the record's
times.total: preprocessing to verification, without loading or training).
Each --variant run (the same experiment
with one setting changed) adds its found / hypothesis / chosen counts with
the change from RUN.

`oracle` asks `posebench recognize --explain --json` about every test
target of a BOP dataset (its test_targets_bop19.json, or --targets) and
prints, per target: the chosen estimate's error, the ground-truth pose
refined and verified like a hypothesis (where verification would rank it,
how many wrong hypotheses rank above it, and how far refinement moved it
away from the ground truth), then the counts: targets where the refined
ground truth would rank above every wrong hypothesis (verification would
choose right if the method had found it),
refinements that turned the ground truth by over 5 degrees, and the median
distance they moved it.

`ar` scores every BOP results file of a reported run (RUN/bop/*_SCENE-*.csv,
`posebench report RUN`) with `posebench score` against the scene's
dataset, on the test targets of the images the run took (an image_stride
run takes some of the dataset's images), and prints BOP's AR and its parts
per method and scene.

Exit 2, naming the file, for a folder without records, a record that does
not fit the record schema, or an answer of posebench that is not the JSON
expected.
"""
import argparse
import collections
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from thesis_report.schema import RECORD_SCHEMA, InputError, load_records  # noqa: E402


def fate(r):
    """What became of one target: found / near / elsewhere / between / none,
    and whether a correct hypothesis existed and was chosen."""
    cr = r.get("correct_rank")
    out = {"hypothesis": cr is not None and cr >= 0, "chosen": cr == 0}
    b = r.get("bop")
    if r["status"] != "ok" or not b:
        out["outcome"] = "none"
        return out
    d = b["diameter"]
    if b["mssd_mm"] < 0.2 * d:
        out["outcome"] = "found"
    else:
        t = r["errors"]["translation_mm_plain"]
        out["outcome"] = "near" if t < 0.25 * d else "elsewhere" if t > d else "between"
    return out


def stage_counts(path, scenes=None):
    """{(scene, method): Counter} and {(scene, method): [seconds]} of a run folder."""
    records = os.path.join(path, "records.jsonl")
    if not os.path.isfile(records):
        raise InputError(f"{path}: no records.jsonl")
    counts = collections.defaultdict(collections.Counter)
    seconds = collections.defaultdict(list)
    for r in load_records(records, RECORD_SCHEMA):
        if scenes and r["scene"] not in scenes:
            continue
        key = (r["scene"], r["descriptor"])
        f = fate(r)
        c = counts[key]
        c["n"] += 1
        c[f["outcome"]] += 1
        c["hypothesis"] += f["hypothesis"]
        c["chosen"] += f["chosen"]
        if r.get("times") is not None and r["status"] == "ok":
            seconds[key].append(r["times"]["total"])
    return counts, seconds


def stages_table(base, variants):
    """Markdown: one row per (scene, method) of the base run; per variant its
    found / hypothesis / chosen and the change."""
    counts, seconds = base
    head = "| scene | method | n | found | hypothesis | chosen | near | elsewhere | none | median s (recognition) |"
    rule = "|---|---|---|---|---|---|---|---|---|---|"
    for label, _ in variants:
        head += f" {label}: found / hyp. / chosen |"
        rule += "---|"
    lines = [head, rule]
    for key in sorted(counts):
        c = counts[key]
        s = seconds.get(key)
        med = f"{statistics.median(s):.2f}" if s else "-"
        row = (f"| {key[0]} | {key[1]} | {c['n']} | {c['found']} | {c['hypothesis']} | {c['chosen']} | "
               f"{c['near']} | {c['elsewhere']} | {c['none']} | {med} |")
        for _, (vc, _) in variants:
            v = vc.get(key)
            if v is None:
                row += " - |"
                continue
            delta = v["found"] - c["found"]
            row += f" {v['found']} ({delta:+d}) / {v['hypothesis']} / {v['chosen']} |"
        lines.append(row)
    return "\n".join(lines)


def rotation_deg(Ra, Rb):
    """Angle (deg) of Ra Rb^T, row-major 3x3 lists."""
    tr = sum(Ra[3 * i + k] * Rb[3 * i + k] for i in range(3) for k in range(3))
    return math.degrees(math.acos(max(-1.0, min(1.0, (tr - 1) / 2))))


def ask(cmd):
    """posebench's JSON answer, or InputError naming the command."""
    p = subprocess.run(cmd, capture_output=True, text=True)
    try:
        return json.loads(p.stdout)
    except json.JSONDecodeError:
        raise InputError(f"{' '.join(cmd)}: exit {p.returncode}, not JSON: {(p.stderr or p.stdout).strip()[:300]}")


def oracle(a):
    """Per target rows and the summary (see the module doc)."""
    targets_file = a.targets or os.path.join(a.dataset, "test_targets_bop19.json")
    try:
        with open(targets_file) as f:
            targets = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        raise InputError(f"{targets_file}: {e}")
    parsed = []
    for t in targets:
        try:
            parsed.append((int(t["scene_id"]), int(t["im_id"]), int(t["obj_id"])))
        except (KeyError, TypeError, ValueError):
            raise InputError(f"{targets_file}: a target without scene_id, im_id and obj_id: {t}")
    # --image-stride as an experiment's image_stride: every n-th image of each scene, in image order.
    images = collections.defaultdict(set)
    for scene, im, _ in parsed:
        images[scene].add(im)
    kept = {(scene, im) for scene, ims in images.items() for im in sorted(ims)[::max(1, a.image_stride)]}
    rows = []
    for scene, im, obj in parsed:
        if (scene, im) not in kept:
            continue
        cmd = [a.posebench, "recognize", "--dataset", a.dataset, "--scene", str(scene), "--image", str(im),
               "--object", str(obj), "--method", a.method, "--refine", a.refine, "--explain", "--json",
               "--seed", str(a.seed)]
        if a.config:
            cmd += ["--config", a.config]
        if a.cache is not None:
            cmd += ["--cache", a.cache]
        j = ask(cmd)
        gt_file = os.path.join(a.dataset, "test", f"{scene:06d}", "scene_gt.json")
        try:
            with open(gt_file) as f:
                gts = [g for g in json.load(f)[str(im)] if g["obj_id"] == obj]
        except (OSError, KeyError, json.JSONDecodeError) as e:
            raise InputError(f"{gt_file}: {e}")
        g = j.get("ground_truth_refined")
        if g is None or not gts or "ranked" not in j:
            raise InputError(f"{' '.join(cmd)}: no ground_truth_refined or ranked in the answer")
        # The GT instance the refined pose came from: the nearest one.
        gt = min(gts, key=lambda x: sum((x["cam_t_m2c"][i] - g["t"][i]) ** 2 for i in range(3)))
        err = j.get("errors") or {}
        # Wrong hypotheses that verification ranks above the refined ground
        # truth (wrong: outside the thesis's table thresholds, 50 mm and
        # 1 - |p.q| < 0.05, i.e. 36.4 degrees).
        wrong_above = 0
        for h in j["ranked"]:
            e = h.get("errors")
            wrong = e is None or not (e["translation_mm"] < 50 and e["rotation_deg"] < 36.4)
            wrong_above += wrong and h["verification"] > g["verification"]
        rows.append({"scene": scene, "im": im, "obj": obj, "wrong_above": wrong_above,
                     "chosen_mm": err.get("translation_mm"), "chosen_correct": bool(err.get("correct")),
                     "hypotheses": len(j["ranked"]), "gt_rank": g["would_rank"],
                     "drift_mm": math.dist(g["t"], gt["cam_t_m2c"]),
                     "drift_deg": rotation_deg(g["R"], gt["cam_R_m2c"])})
    return rows


def oracle_report(rows, method):
    n = len(rows)
    first = sum(r["wrong_above"] == 0 for r in rows)
    drift = sum(r["drift_deg"] > 5 for r in rows)
    med_mm = statistics.median(r["drift_mm"] for r in rows) if rows else 0.0
    correct = sum(r["chosen_correct"] for r in rows)
    lines = ["| scene | image | object | chosen: error mm | correct | ground truth refined: would rank | wrong ones above it | "
             "drift mm | drift deg |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ch = "-" if r["chosen_mm"] is None else f"{r['chosen_mm']:.0f}"
        lines.append(f"| {r['scene']} | {r['im']} | {r['obj']} | {ch} | {'yes' if r['chosen_correct'] else 'no'} | "
                     f"{r['gt_rank']} of {r['hypotheses']} | {r['wrong_above']} | {r['drift_mm']:.1f} | {r['drift_deg']:.1f} |")
    lines.append("")
    lines.append(f"{method}: {n} targets; chosen correct {correct}; the refined ground truth would rank above every "
                 f"wrong hypothesis {first}; refinement turned the ground truth by over 5 deg {drift} (moved it by {med_mm:.1f} mm at the median)")
    return "\n".join(lines)


def run_images(path):
    """{scene: {(scene_id, im_id)}} of the run's records."""
    out = collections.defaultdict(set)
    for r in load_records(os.path.join(path, "records.jsonl"), RECORD_SCHEMA):
        out[r["scene"]].add((r["scene_id"], r["im_id"]))
    return out


def average_recalls(a):
    """[(method, scene, AR, AR_MSSD, AR_MSPD, AR_VSD, targets)] of a reported run."""
    datasets = {}
    for d in a.dataset:
        scene, sep, path = d.partition("=")
        if not sep or not scene:
            raise InputError(f"--dataset {d}: expected SCENE=DIR")
        datasets[scene] = path
    images = run_images(a.run)
    bop = os.path.join(a.run, "bop")
    if not os.path.isdir(bop):
        raise InputError(f"{bop}: no BOP results (run `posebench report {a.run}` first)")
    rows = []
    with tempfile.TemporaryDirectory(prefix="real_diagnosis_") as work:
        for name in sorted(os.listdir(bop)):
            stem, ext = os.path.splitext(name)
            method, sep, dataset_split = stem.rpartition("_")
            scene = dataset_split.rsplit("-", 1)[0]
            if ext != ".csv" or not sep or scene not in datasets:
                continue
            targets_file = os.path.join(datasets[scene], "test_targets_bop19.json")
            try:
                with open(targets_file) as f:
                    targets = [t for t in json.load(f) if (t["scene_id"], t["im_id"]) in images[scene]]
            except (OSError, KeyError, TypeError, json.JSONDecodeError) as e:
                raise InputError(f"{targets_file}: {e}")
            tf = os.path.join(work, f"{stem}_targets.json")
            with open(tf, "w") as f:
                json.dump(targets, f)
            out = os.path.join(work, stem)
            cmd = [a.posebench, "score", os.path.join(bop, name), "--dataset", datasets[scene], "--targets", tf,
                   "--out", out, "--quiet"]
            p = subprocess.run(cmd, capture_output=True, text=True)
            try:
                with open(os.path.join(out, "scores.json")) as f:
                    sc = json.load(f)
            except (OSError, json.JSONDecodeError):
                raise InputError(f"{' '.join(cmd)}: exit {p.returncode}, no scores: {p.stderr.strip()[:300]}")
            rows.append((method, scene, sc["bop19_average_recall"], sc["bop19_average_recall_mssd"],
                         sc["bop19_average_recall_mspd"], sc["bop19_average_recall_vsd"], sc["targets_count"]))
    return rows


def ar_table(rows):
    lines = ["| method | scene | targets | AR | AR_MSSD | AR_MSPD | AR_VSD |", "|---|---|---|---|---|---|---|"]
    for m, scene, ar, mssd, mspd, vsd, n in rows:
        lines.append(f"| {m} | {scene} | {n} | {ar:.3f} | {mssd:.3f} | {mspd:.3f} | {vsd:.3f} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    st = sub.add_parser("stages", help="per scene and method, what became of each target")
    st.add_argument("run")
    st.add_argument("--variant", action="append", default=[], help="LABEL=RUN: the same experiment, one change")
    st.add_argument("--scenes", nargs="*", help="only these scenes")
    orc = sub.add_parser("oracle", help="the ground truth refined and verified as a hypothesis, per target")
    orc.add_argument("--dataset", required=True)
    orc.add_argument("--method", required=True)
    orc.add_argument("--refine", default="icp_plane")
    orc.add_argument("--targets")
    orc.add_argument("--image-stride", type=int, default=1)
    orc.add_argument("--config")
    orc.add_argument("--cache")
    orc.add_argument("--seed", type=int, default=1)
    orc.add_argument("--posebench", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build",
                                                          "posebench"))
    arp = sub.add_parser("ar", help="BOP's AR of every results file of a reported run")
    arp.add_argument("run")
    arp.add_argument("--dataset", action="append", default=[], help="SCENE=DIR: the dataset of a scene of the run")
    arp.add_argument("--posebench", default=orc.get_default("posebench"))
    a = ap.parse_args(argv)
    try:
        if a.cmd == "stages":
            variants = []
            for v in a.variant:
                label, sep, path = v.partition("=")
                if not sep or not label:
                    raise InputError(f"--variant {v}: expected LABEL=RUN")
                variants.append((label, stage_counts(path, a.scenes)))
            base = stage_counts(a.run, a.scenes)
            if not base[0]:
                raise InputError(f"{a.run}: no records of the scenes asked for")
            print(stages_table(base, variants))
        elif a.cmd == "ar":
            print(ar_table(average_recalls(a)))
        else:
            print(oracle_report(oracle(a), a.method))
    except InputError as e:
        print(f"real_diagnosis.py: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
