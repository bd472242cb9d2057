#!/usr/bin/env python3
"""Writes results/thesis/README.md and cells.csv from the raw results of scripts/thesis.sh.

    scripts/thesis_report.py OUT EXPERIMENT... [--ablations FILE] [--scorecard-json FILE]

--scorecard-json FILE: write only the agreement scorecard and the verdicts as
JSON to FILE ("-": stdout), no README. --ablations FILE: the ablation pairs
(default configs/thesis/ablations.yaml; a missing file means none).

OUT is results/thesis: each experiment's folder OUT/raw/NAME holds what
`posebench run` and `posebench report` wrote (experiment.json, records.jsonl,
runs.jsonl, report.md, report.csv, plots.json); merged plots go to OUT/plots.
Every record is checked against the trial record's schema (`posebench schema
record` of the binary in POSEBENCH, default build/posebench, or the copy
RECORD_SCHEMA below when there is no binary): an unknown key or a missing
required key is an error naming the file, the line and the key (exit code 2).
The README's numbers all come from those files: each robustness cell of a
table experiment counted from its records (k of n correct, the 95% Wilson
interval, Fisher's exact test against the thesis's k of n; the thesis's
value from report.csv), the other rows from report.md, wall times and loads
from runs.jsonl (one line per `posebench run` that ran trials; folders of
older runs: their run_seconds.txt), the milk carton's "faces on faces" row
from each record's judgements.faces. OUT/cells.csv has every cell (CSV_COLUMNS).
The agreement scorecard, the verdicts on the thesis's conclusions (rules in
scripts/thesis_verdicts.py) and the ablation section (pairs of experiments
from the ablations file) are computed from the same cells. A missing thesis
value or a malformed file is an error naming file and field (exit code 2).
Without any experiment's records the README is left as it is. Environment:
JOBS (worker processes, for the text).
"""
import collections
import csv
import datetime
import difflib
import json
import os
import statistics
import subprocess
import sys

import thesis_ablations
from thesis_stats import count_of, fisher_exact, fitting_n, kendall_tau, printable_as_count, wilson, within_points
from thesis_verdicts import Curve, Data, evaluate

# ---- the trial record's schema ------------------------------------------------
# A copy of `posebench schema record` ("fields"; src/eval/record.cpp), used
# when no binary is at hand; tests/scripts compare it with the binary's.


def _struct(*fields):
    """An object schema from (key, schema, required) triples."""
    return {"type": "object", "fields": {k: dict(s, required=req) for k, s, req in fields}}


STRING, INTEGER, NUMBER, BOOLEAN, ARRAY = ({"type": t} for t in ("string", "integer", "number", "boolean", "array"))
FREE = {"type": "object", "free": True}
POSE = _struct(("R", ARRAY, True), ("t", ARRAY, True))
TIMES = _struct(*((k, NUMBER, True) for k in ("preprocess", "describe", "match", "group", "initial_pose", "refine",
                                              "verify", "total")))
ERRORS = _struct(("translation_mm", NUMBER, True), ("rotation_1mpq", NUMBER, True), ("rotation_deg", NUMBER, True),
                 ("symmetry", INTEGER, True), ("translation_mm_plain", NUMBER, True),
                 ("rotation_1mpq_plain", NUMBER, True))
BOP = _struct(("mssd_mm", NUMBER, True), ("mspd_px", NUMBER, True), ("vsd", ARRAY, True), ("diameter", NUMBER, True),
              ("image_width", INTEGER, True))
JUDGEMENT = _struct(("correct", BOOLEAN, True), ("translation_mm", NUMBER, True), ("rotation_1mpq", NUMBER, True))
INSTANCE = _struct(("estimate", POSE, True), ("score", NUMBER, True), ("inliers", INTEGER, True),
                   ("correct", BOOLEAN, False))
# "required": True = in every record, False = when the trial got that far,
# "when_ok" = in every record with status ok, "when_gt" = in every record with
# status ok and a ground truth (`gt`): the judged ones.
OK, GT = "when_ok", "when_gt"
RECORD_SCHEMA = _struct(
    ("key", STRING, True), ("scene", STRING, True), ("scenario", STRING, True), ("dataset", STRING, True),
    ("split", STRING, True), ("scene_id", INTEGER, True), ("im_id", INTEGER, True), ("descriptor", STRING, True),
    ("refinement", STRING, True), ("inst_count", INTEGER, False), ("params", FREE, True), ("added_noise_mm", NUMBER, True), ("settings", FREE, True),
    ("seed", INTEGER, True), ("status", STRING, True), ("correct", BOOLEAN, GT), ("wall_s", NUMBER, OK),
    ("message", STRING, False), ("obj_id", INTEGER, OK), ("settings_resolved", FREE, OK), ("train_s", NUMBER, OK),
    ("train_from_cache", BOOLEAN, OK), ("times", TIMES, OK), ("hypotheses", INTEGER, OK), ("correct_rank", INTEGER, False),
    ("init", POSE, False),
    ("estimate", POSE, OK), ("instances", {"type": "array", "items": INSTANCE}, False), ("score", NUMBER, OK), ("inliers", INTEGER, OK), ("gt", POSE, False),
    ("visib_fract", NUMBER, False), ("errors", ERRORS, GT), ("bop", BOP, GT),
    ("judgements", {"type": "object", "values": JUDGEMENT}, False))

PY_TYPES = {"string": (str,), "integer": (int,), "number": (int, float), "boolean": (bool,), "array": (list,),
            "object": (dict,)}


class InputError(Exception):
    """A results file that cannot be read as it should: names file, line and key."""


class KeyProblem(Exception):
    """A record's key (dotted path) that does not fit the schema: `what 'key'detail`."""

    def __init__(self, key, what, detail=""):
        super().__init__(key, what, detail)
        self.key, self.what, self.detail = key, what, detail

    def __str__(self):
        return "%s '%s'%s" % (self.what, self.key, self.detail)


def schema_from_binary(binary):
    """The schema `BINARY schema record` prints, or None without a binary."""
    if not binary or not os.access(binary, os.X_OK):
        return None
    try:
        r = subprocess.run([binary, "schema", "record"], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    try:
        return {"type": "object", "fields": json.loads(r.stdout)["fields"]} if r.returncode == 0 else None
    except (ValueError, KeyError, TypeError):
        return None


def is_required(flag, record):
    """Whether a key is required in `record`, by its schema's "required"."""
    if flag in ("when_ok", "when_gt"):
        return record.get("status") == "ok" and (flag == "when_ok" or "gt" in record)
    return flag is True


WHEN = {"when_ok": " (required with status ok)", "when_gt": " (required with status ok and gt)"}


def check_value(value, spec, record, path):
    """Raises KeyProblem(key path, what) where `value` does not fit `spec`."""
    ok = isinstance(value, PY_TYPES.get(spec.get("type"), (object,))) and not (isinstance(value, bool) and spec["type"] in
                                                           ("integer", "number"))
    if not ok:
        raise KeyProblem(path, "wrong type for key", " (%s, expected %s)" % (type(value).__name__, spec["type"]))
    if "values" in spec:
        for k, v in value.items():
            check_value(v, spec["values"], record, path + "." + k)
    elif "items" in spec:
        for i, v in enumerate(value):
            check_value(v, spec["items"], record, "%s[%d]" % (path, i))
    elif "fields" in spec:
        check_fields(value, spec["fields"], record, path)


def check_fields(obj, fields, record, path=""):
    prefix = path + "." if path else ""
    for k in obj:  # unknown keys first: a misspelt key is named as such
        if k not in fields:
            close = difflib.get_close_matches(k, list(fields), n=1)
            raise KeyProblem(prefix + k, "unknown key", " (did you mean '%s'?)" % close[0] if close else "")
    for k, spec in fields.items():
        if k in obj:
            check_value(obj[k], spec, record, prefix + k)
        elif is_required(spec.get("required"), record):
            raise KeyProblem(prefix + k, "missing required key", WHEN.get(spec.get("required"), ""))


def parse_record(line, schema, path, n):
    """Line n of a records.jsonl as a record that fits the schema."""
    try:
        r = json.loads(line)
    except ValueError as e:
        raise InputError("%s: line %d: not JSON (%s)" % (path, n, e)) from None
    if not isinstance(r, dict):
        raise InputError("%s: line %d: not a JSON object" % (path, n))
    try:
        check_fields(r, schema["fields"], r)
    except KeyProblem as p:
        raise InputError("%s: line %d: %s" % (path, n, p)) from None
    return r


def load_records(path, schema):
    """Every record of a records.jsonl, each checked against the schema."""
    with open(path) as f:
        return [parse_record(line, schema, path, n) for n, line in enumerate(f, 1) if line.strip()]


class Runs:
    """What a folder says of its `posebench run` invocations that ran trials:
    wall seconds, 15-minute loads at their ends, trials ran; `source` is the
    file read (runs.jsonl, or run_seconds.txt of older runs), None without."""

    def __init__(self, seconds=0.0, loads=(), ran=0, source=None):
        self.seconds, self.loads, self.ran, self.source = seconds, list(loads), ran, source

    @property
    def known(self):
        return self.source is not None

    def add(self, wall, ran, load):
        self.seconds += wall
        self.ran += ran
        if load is not None:
            self.loads.append(load)


def load_runs(path):
    """Wall seconds (sum of wall_s), 15-minute loads at the end (load15_end)
    and trials ran (sum of ran), over the lines of a runs.jsonl with "ran" > 0."""
    if not os.path.exists(path):
        return Runs()
    runs = Runs(source="runs.jsonl")
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if not line.strip():
                continue
            try:
                r = json.loads(line)
                ran, wall = int(r["ran"]), float(r["wall_s"])
                load = None if r.get("load15_end") is None else float(r["load15_end"])
            except (ValueError, TypeError, KeyError, AttributeError) as e:
                raise InputError("%s: line %d: not a run summary (%s: %s)" % (path, n, type(e).__name__, e))
            if ran > 0:
                runs.add(wall, ran, load)
    return runs


def load_run_seconds(path):
    """The same from the run_seconds.txt that scripts/thesis.sh kept before
    runs.jsonl existed: one line per invocation that ran trials,
    `DATE TIME WALL_SECONDS RAN JOBS LOAD15`."""
    if not os.path.exists(path):
        return Runs()
    runs = Runs(source="run_seconds.txt")
    with open(path) as f:
        for n, line in enumerate(f, 1):
            fields = line.split()
            if not fields:
                continue
            try:
                runs.add(float(fields[2]), int(fields[3]), float(fields[5]) if len(fields) > 5 else None)
            except (ValueError, IndexError) as e:
                raise InputError("%s: line %d: not `DATE TIME WALL_SECONDS RAN JOBS LOAD15` (%s)" % (path, n, e))
    return runs


def load_folder_runs(d):
    """runs.jsonl of a results folder, else its older run_seconds.txt."""
    runs = load_runs(os.path.join(d, "runs.jsonl"))
    return runs if runs.known else load_run_seconds(os.path.join(d, "run_seconds.txt"))


# ---- the experiments' folders ---------------------------------------------------


def read_json(path, default):
    if not os.path.exists(path):
        return default
    with open(path) as f:
        return json.load(f)


def read_text(path):
    if not os.path.exists(path):
        return ""
    with open(path) as f:
        return f.read()


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


class Experiment:
    """One folder OUT/raw/NAME: config, records, report and runs."""

    def __init__(self, name, exp, records, md="", rows=(), plots=(), runs=None):
        self.name, self.exp, self.records, self.md = name, exp, records, md
        self.rows, self.plots, self.runs = list(rows), list(plots), runs or Runs()


def load_experiment(raw, name, schema):
    """An experiment's folder, or None when it has no records yet."""
    d = os.path.join(raw, name)
    if not os.path.exists(os.path.join(d, "records.jsonl")):
        return None
    return Experiment(name, read_json(os.path.join(d, "experiment.json"), None),
                      load_records(os.path.join(d, "records.jsonl"), schema),
                      read_text(os.path.join(d, "report.md")), read_csv(os.path.join(d, "report.csv")),
                      read_json(os.path.join(d, "plots.json"), []), load_folder_runs(d))


class Results:
    """The loaded experiments (in the order given, then those only an
    ablation names: `ablation_only`), `partner`: ablated experiment -> the
    experiment it is paired with, and where plots go. An experiment named on
    the command line stays what it is (a main table, a variant, a figure)
    even when an ablation also pairs it."""

    def __init__(self, experiments, raw="", plots="", ablation_only=(), partner=None):
        self.x = {e.name: e for e in experiments}
        self.raw, self.plots = raw, plots
        self.ablation_only, self.partner = set(ablation_only), dict(partner or {})

    def __contains__(self, e):
        return e in self.x

    def __getitem__(self, e):
        return self.x[e]

    def cell(self, e, scene, measure, method, cond=""):
        """The row of an experiment's report.csv, or None."""
        if e not in self.x:
            return None
        for r in self.x[e].rows:
            if r["scenario"] == scene and r["measure"] == measure and r["method"] == method and r["condition"] == cond:
                return r
        return None

    def thesis(self, e, scene, measure, method):
        """The thesis's value beside a cell (None when it printed none)."""
        r = self.cell(e, scene, measure, method)
        return float(r["thesis"]) if r and r["thesis"] != "" else None

    def scenes_of(self, e):
        return [s["name"] for s in self.x[e].exp["scenes"]] if e in self.x else []

    def images_of(self, e):
        n = set()
        for s in self.x[e].exp["scenes"]:
            n.add(s.get("generator", {}).get("images", s.get("images", 0)) or "all")
        return ", ".join(str(i) for i in sorted(n, key=str))

    def table_images(self):
        return self.images_of("table_4_1") if "table_4_1" in self else "fewer"

    def totals(self):
        """Wall seconds and trials over every experiment."""
        return (sum(x.runs.seconds for x in self.x.values()), sum(len(x.records) for x in self.x.values()))


def load_results(out_dir, experiments, schema, ablations=()):
    """The experiments named, then those of the ablations' pairs not among
    them (each folder without records is left out)."""
    raw = os.path.join(out_dir, "raw")
    loaded = [load_experiment(raw, e, schema) for e in experiments]
    partner, extra = {}, []
    for a in ablations:
        for e, e2 in a["pairs"]:
            partner.setdefault(e2, e)
            for name in (e, e2):
                if name not in experiments and name not in extra:
                    extra.append(name)
    more = [load_experiment(raw, e, schema) for e in extra]
    return Results([x for x in loaded + more if x is not None], raw, os.path.join(out_dir, "plots"),
                   [x.name for x in more if x is not None], partner)


# ---- formatting -------------------------------------------------------------------


def pct(v):
    return "-" if v is None else "%.0f%%" % (100 * v)


def mean(v):
    v = [a for a in v if a is not None]
    return sum(v) / len(v) if v else None


def fmt_dur(s):
    s = int(round(s))
    return "%dh%02dm%02ds" % (s // 3600, s // 60 % 60, s % 60) if s >= 3600 else "%dm%02ds" % (s // 60, s % 60)


def compact(v):
    return json.dumps(v, separators=(", ", ": "))


TITLES = {
    "table_4_1": "Table 4.1: LS5, several model views (12 synthetic, 8 real-sensor)",
    "table_4_3": "Table 4.3: LS5, one model view (from the side)",
    "table_4_4": "Table 4.4: LS5, one view, CRH skipped",
    "table_4_5": "Table 4.5: milk carton",
    "table_4_7": "Table 4.7: Statue of Liberty (armadillo stand-in)",
    "table_4_9": "Table 4.9: registration alone, statue, warehouse",
    "fig_4_6": "Figure 4.6: robustness and time vs number of hypotheses",
    "fig_4_7_global": "Figure 4.7 (global part): LS5 robustness vs added noise, CVFH CESF, 1 view",
    "fig_4_7_local": "Figure 4.7 (local part): LS5 robustness vs added noise, SHOT FPFH, 12 views",
    "fig_4_11_global": "Figure 4.11 (global part): statue robustness vs added noise, CVFH CESF, 1 view",
    "fig_4_11_local": "Figure 4.11 (local part): statue robustness vs added noise, SHOT FPFH, 12 views",
    "fig_4_12": "Figure 4.12: registration robustness vs added noise",
}
TABLES = ["table_4_1", "table_4_3", "table_4_4", "table_4_5", "table_4_7",
          "table_4_9"]


def short_title(e):
    return TITLES.get(e, e).split(":")[0]


# ---- the README's sections, each a list of text blocks ------------------------------



def section_intro(res, host):
    total, ntrials = res.totals()
    o = ["# The thesis, regenerated\n",
         "Generated by `scripts/thesis.sh` on %s from the raw records in `results/thesis/raw/` (not committed). "
         "Every number below was measured by that run; the thesis's value, where it printed one, is in parentheses "
         "(from `configs/thesis/reference.yaml`, i.e. THESIS.md).\n" % host["date"],
         "**Total wall time of the regeneration: %s** for %d trials, on a %d-core machine (%s), %s worker processes, "
         "each single-threaded." % (fmt_dur(total), ntrials, host["cores"], host["cpu"] or "cpu unknown",
                                    host["jobs"])]
    loads = [l for x in res.x.values() for l in x.runs.loads]
    try:
        jobs = float(host["jobs"])
    except (TypeError, ValueError):
        jobs = float(host["cores"])
    if loads and max(loads) > jobs + 0.5:
        o.append("The machine was shared with other jobs while it ran: the 15-minute load average at the end of the "
                 "experiments ranged from %.1f to %.1f on %d cores, more than the run's own workers, so wall times "
                 "(and the per-image times in the tables, which are wall-clock times of the online computation inside "
                 "a worker) are inflated by the competition for the CPU." % (min(loads), max(loads), host["cores"]))
    elif loads:
        o.append("The 15-minute load average at the end of the experiments ranged from %.1f to %.1f on %d cores: the "
                 "run's own workers, no other load." % (min(loads), max(loads), host["cores"]))
    return o + ["\n"]


def section_reproduce():
    return [
        "## Reproduce\n",
        "```sh\ncmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build --target posebench\n"
        "scripts/thesis.sh --ablations   # all experiments and the ablations; resumable (re-running does only what "
        "is missing)\n"
        "scripts/thesis.sh --only table_4_1 --jobs 2    # one experiment\n"
        "scripts/thesis.sh --readme-only                # rewrite this file from the raw records\n"
        "scripts/thesis_report.py results/thesis EXPERIMENT... --scorecard-json FILE  # the scorecard and verdicts "
        "as JSON\n```\n",
        "Each experiment is `posebench run configs/thesis/NAME.yaml --out results/thesis/raw/NAME --jobs 2 --cache "
        "cache --scenes scenes` followed by `posebench report results/thesis/raw/NAME --format md,csv --plots`. The "
        "scene sets are generated on the first run into `scenes/` from `configs/scenes/*.yaml` (deterministic: same "
        "seed, same bytes).\n"]


DIFFERENCES = [
    "Objects: the LS5 is a procedural LS5-like unit (`models/models.yaml`: `ls5`, symmetric about its vertical "
    "axis for the evaluation, as the thesis judged it); the Statue of Liberty is stood in for by the Stanford "
    "armadillo, 126 mm tall on the table (`armadillo`) and scaled to exactly 1500 mm in the warehouse "
    "(`configs/scenes/thesis_statue_warehouse.yaml`: the warehouse generator scales every model to "
    "`warehouse.object_size_mm`, here fixed at 1500, so the statue has the size of the registry's "
    "`liberty_warehouse` while keeping the name `armadillo` that one experiment needs for both scenarios; its "
    "warehouse distractors are 1500 mm too); the milk carton is the procedural gable-top `milk_carton`. The "
    "thesis's statue measures 1500 x 450 x 380 mm in the warehouse and a tenth of that on the table; the "
    "armadillo at the same height is 106 x 95 mm across on the table, about three times as wide and deep. The "
    "statue ablation runs Table 4.7 with the armadillo squeezed to the statue's bounding box (`liberty_slender`: "
    "38 x 32 x 126 mm, 1500 mm tall in the warehouse).",
    "Real sensors: the thesis's Fotonic Astra and Kinect One recordings had no ground truth (judged by eye); here "
    "they are simulated sensors (`astra`, `kinect_one`) rendering generated table scenes with ground truth. The "
    "`astra` model is calibrated on real structured-light frames (noise, depth steps and grazing-angle losses per "
    "distance: `results/sensors/`); it does not lose data on dark or shiny surfaces as real sensors do. The "
    "`kinect_one` model's noise level is calibrated on two real Kinect v2 frames, and its mixed (\"flying\") "
    "pixels at depth edges fitted to them, though they do not pin those down (`results/sensors/`): "
    "distance-dependent noise, and mixed pixels at three in four "
    "pixels next to a depth edge of more than 30 mm, of which the driver's edge filter drops those in the middle "
    "of a large jump, as the Kinect One's driver does (libfreenect2's `EnableEdgeAwareFilter`, on by default; "
    "`TimeOfFlightNoise` in `src/render/sensor.h`); it loses far less data than the real frames, near edges and "
    "away from them. The sensor ablation runs the Astra rows with the model before its calibration, the tof "
    "ablation the Kinect One rows with theirs; the edges ablation runs the Kinect One rows without mixed pixels.",
    "Occlusion: the thesis's occluded sets had \"some small amount of occlusion\"; here the target is 70-95% "
    "visible in them (`occlusion.visib_fract` in the thesis configs). The occlusion ablation runs them at 40-90%, "
    "the set-up before issue 10.",
    "Images: %s per scene set in the tables (the thesis's sizes: 30 per synthetic set, 60 per real sensor and 20 "
    "occluded); the figures' points: see the table below (the thesis: 30 per noise level).",
    "Scene set-up, as read from the thesis. Its text gives no camera height or elevation, and its figures of the "
    "scenes (4.3-4.5) are not in the text we have. The table scenes here are seen from 0.6-1.5 m at 30-70 degrees "
    "above the table (`configs/scenes/table_*.yaml`, `thesis_*`), the warehouse from 2-5 m at 5-30 degrees. The "
    "thesis chose its model views by hand (\"the viewpoints of these are manually chosen\") and rendered its "
    "single view \"from the side, so no top nor bottom were captured\"; its one-view results (Table 4.3: CVFH "
    "70-80% on the real scenes) only fit scenes seen from near that view. So the training views are rendered at "
    "the middle of each scene set's elevation range (`views.follow_scene`: 50 degrees on the tables, 17.5 in the "
    "warehouse): the ring of 8 and the single view at that elevation, the 4 extra views of the 12-view layout from "
    "below (-45 degrees), as the thesis. The views ablation runs Tables 4.1, 4.3 and 4.4 with the earlier layout "
    "(ring at 20 degrees, single view at 0).",
    "Warehouse: one plane, the floor (`warehouse.wall: false` in the thesis configs), as the thesis's \"a plane "
    "was added behind the objects to simulate a floor or a wall\"; preprocessing removes one plane "
    "(`preprocess.max_planes: 1`), as the thesis. The planes ablation runs the warehouse rows with a floor and a "
    "wall, the set-up before issue 10. The warehouse's occluded images (half of them, the target 40-90% visible) "
    "follow the thesis's \"a mix of totally visible objects and occluded ones\"; its discussion speaks of a "
    "\"fairly high amount of occlusion\" without numbers, and the cover ablation runs the warehouse rows with the "
    "occluded half 20-60% visible.",
    "Lengths the thesis does not give follow the default profile, relative to the object's diameter (issue 9; "
    "`settings_resolved` in every record has them in mm): normal radius 0.1 d (in the warehouse, where that ball "
    "spans many 20 mm voxels, its PCA runs on the cloud's centroids at 40 mm: `preprocess.normal_coarse_support`, "
    "`results/bench/README.md`, twenty-third round), RANSAC plane threshold 0.05 d, "
    "FPFH/SHOT radius 0.3 d, LRF radius 0.2 d, cluster distance 0.1 d, CVFH region distance 0.075 d and normal "
    "radius 0.1 d, ICP correspondence distance 0.1 d, inlier threshold 0.05 d but at most 2 voxels "
    "(`verify.inlier_threshold_max_voxels`: 40 mm in the warehouse, where 0.05 d is 90 mm, 4.5 voxels, and let the "
    "LS5 turned by 180 degrees score as many inliers as the right pose; the tables' 0.05 d is 0.9-1.5 voxels; "
    "the cap moved the warehouse cells of the 12 experiments from 2497 to 2589 of 3330 correct, and no table "
    "estimate). Table 4.2's voxel, keypoint voxel "
    "and Hough bin stay in mm, and so does the warehouse's 9 m range cut. The tutorial ablation runs the table "
    "scenes' SHOT and FPFH with the values of PCL's correspondence-grouping tutorial, which the thesis's local "
    "pipeline follows step by step (descriptor radius 20 mm, frame radius 15 mm, SHOT matches under 0.25; "
    "`results/thesis/FINDINGS.md`, \"The local descriptors' support\"). Before issue 9 the warehouse had "
    "hand-scaled mm values (normal radius 60, descriptor radius 120, inlier threshold 30, ...); going relative "
    "changed the warehouse cells from 607 to 630 correct (Figure 4.11 local 46 -> 67 of 70, Table 4.3 23 -> 15 "
    "of 50) and the run from 17 to 27 minutes.",
    "Table 4.9 and Figure 4.12: the thesis refined the hypotheses that some recognition method had made converge; "
    "here each method refines the ground-truth pose perturbed by a seeded random rotation and translation "
    "(`perturb_deg`, `perturb_mm` in the config: 15 degrees and 50 mm). The start ablation runs Table 4.9 from "
    "30 degrees and 100 mm. Registration keeps reciprocal nearest pairs within 0.1 d in a crop of the scene "
    "around the hypothesis (ICP, ICP-LM, ICP-plane), where pcl::IterativeClosestPoint, which the thesis used, "
    "pairs every point with its nearest at any distance in the whole target; the pclicp ablation runs it so.",
    "Figures 4.7 and 4.11: the thesis used one model view for CVFH/CESF and 12 for SHOT/FPFH. An experiment has "
    "one view count per scene set, so each figure is two experiments (`_global`, `_local`), drawn in one plot. "
    "The scenes are rendered without sensor noise and the noise of each level is added per trial.",
    "The milk carton is judged with the symmetries of `models/models.yaml` (stricter than the thesis; see Table "
    "4.5 for both judgments).",
    "ESF is the project's own seeded implementation (PCL's ESFEstimation reseeds the C generator from the clock); "
    "the thesis used PCL's. ESF has no surface frame: its initial pose aligns the rays from the camera to the two "
    "clouds' centroids, where the thesis's section 3.2.4 aligns the clusters' average normals for every global "
    "descriptor; the esfpose ablation runs ESF that way. It draws 20,000 point triples (PCL's value), where the "
    "thesis's section 3.2.3 iterates \"the number of points\" (the triples ablation), and takes its roll from the "
    "CRH, which needs normals the thesis's ESF does not compute (the esfroll ablation skips it). The esfread "
    "ablation switches these readings and the nearest one at once.",
    "Synthetic table: the LS5 stands upright in half of the images and lies in another rest pose in the other "
    "half (`target_upright_probability: 0.5`); the thesis's synthetic LS5 is \"slightly tilted\" and \"not "
    "standing upright\". The tilt ablation stands it upright, leaned by up to 20 degrees (`target_tilt_deg`).",
    "CESF follows the thesis's definition (CVFH's stable regions after high-curvature removal, an ESF per region, "
    "the CRH roll), and, as CVFH, describes a cloud without a stable region by the ESF of all of it. Why it trails "
    "CVFH (an ESF of one smooth region looks like a smooth region of a distractor, so the right pair ranks below "
    "the top 5) and why Table 4.9's accuracy order is inverted (reciprocal correspondences) is measured in "
    "`results/thesis/FINDINGS.md`. The cesf ablation runs CESF with the other reading of its definition, the ESF "
    "of the whole cluster posed from each stable region (`global.cesf_whole_cluster`).",
    "Global hypotheses: the top five matches (`global.top_k`) go on, each with up to three CRH roll peaks "
    "(`global.crh_max_peaks`), so up to 15 hypotheses are refined; the thesis passes \"the top five hypotheses\" "
    "to refinement and makes a new hypothesis of each distinguished CRH peak. The rolls ablation counts five "
    "hypotheses after the CRH instead (`global.top_k_counts_rolls`). The five are the nearest of every "
    "(scene signature, model signature) pair of the image, so one scene cluster can bring several training views; "
    "the thesis's section 3.2.3 runs \"a nearest neighbour search\" for each scene histogram among the model "
    "histograms before keeping the top hypotheses. The nearest ablation keeps each scene signature's nearest model "
    "signature only (`global.matches_per_signature: 1`). CVFH's and CESF's initial pose aligns the regions' "
    "negated mean normals and takes the CRH about them, where pcl::CRHEstimation (and the thesis's CRH text) "
    "projects the normals about the camera-to-centroid ray; the rayaxis ablation uses that ray "
    "(`global.view_ray_axis`). CVFH's and CESF's stable regions grow with lengths relative to the object and "
    "our thresholds, where the thesis changed only its tables' parameters between scenarios and took CVFH from "
    "PCL; the pclcvfh ablation uses pcl::CVFHEstimation's defaults in every scenario.",
    "The text ablation switches every reading above that follows the thesis's text or the PCL defaults it used "
    "(statue, tilt, free, cover, tutorial, pclicp, pclcvfh, rayaxis, literal, triples, esfpose) at once, for "
    "CVFH, CESF, SHOT and FPFH; the textesf ablation does the same for ESF with esfroll's switch too. A gap that "
    "no single reading closes can be the sum of several; these two show whether it is.",
    "Times are wall-clock seconds of the online computation of one image (training views excluded: they are "
    "rendered and described once and cached), single-threaded; the load column of the experiments table says "
    "what else ran on the machine.",
]


def section_differences(res):
    lines = [d % res.table_images() if "%s" in d else d for d in DIFFERENCES]
    return ["## How this run differs from the thesis\n"] + ["- " + line for line in lines] + [""]


def trials_per_cell(res, e):
    """Our trials per cell (per point for the figures) of an experiment, from its records: `10` or `5-10`."""
    ns = [len(recs) for recs in group_records(res, res[e]).values()]
    return "-" if not ns else ("%d" % ns[0] if min(ns) == max(ns) else "%d-%d" % (min(ns), max(ns)))


def experiment_row(res, e):
    """A row of the experiments table: sizes, statuses, time and loads from runs.jsonl."""
    x = res[e]
    st = {}
    for r in x.records:
        st[r["status"]] = st.get(r["status"], 0) + 1
    config = ("`configs/thesis/ablations.yaml` (derived: `raw/configs/%s.yaml`)" % e if e in res.ablation_only
              else "`configs/thesis/%s.yaml`" % e)
    return "| %s | %s | %s | %s | %d | %s | %s | %s |" % (
        short_title(e), config, res.images_of(e), trials_per_cell(res, e), len(x.records),
        ", ".join("%s %d" % kv for kv in sorted(st.items())),
        fmt_dur(x.runs.seconds) if x.runs.seconds else "-", "/".join("%.1f" % l for l in x.runs.loads) or "-")


def resolution_text(res):
    """What n trials per cell can tell apart, for each n of the table experiments."""
    ns = sorted({len(recs) for e, x in res.x.items() if table_of(x) for recs in group_records(res, x).values()})
    out = []
    for n in ns:
        lo, hi = wilson(n // 2, n)
        first = next((k for k in range(n + 1) if fisher_exact(0, n, k, n) < 0.05), None)
        out.append("at n = %d the 95%% Wilson interval of %d/%d is %.0f-%.0f%%%s" % (
            n, n // 2, n, 100 * lo, 100 * hi,
            ", and 0 of %d against k of %d first differ at p < 0.05 (Fisher) for k = %d" % (n, n, first)
            if first is not None else ""))
    return "; ".join(out)


def section_experiments(res):
    total, ntrials = res.totals()
    o = ["## Experiments, sizes and times\n",
         "| experiment | config | images per scenario | trials per cell | trials | status | wall time | load |",
         "|---|---|---|---|---|---|---|---|"]
    o += [experiment_row(res, e) for e in res.x]
    o.append("| **total** | | | | %d | | **%s** | |\n" % (ntrials, fmt_dur(total)))
    o.append("Trials per cell: records per scene set and method (per point of a figure), counted from the records. "
             "Wall time: the sum over the `posebench run` invocations that ran trials (an interrupted and resumed run "
             "counts all its parts; scene generation included). Load: the machine's 15-minute load average at the "
             "end of each invocation (2 cores; other work was running), so per-image times of different experiments "
             "were measured under different competition for the CPU.\n")
    unknown = [e for e, x in res.x.items() if not x.runs.known]
    if unknown:
        o.append("No `runs.jsonl` (nor the `run_seconds.txt` of older runs), so no wall time or load: %s.\n" %
                 ", ".join(unknown))
    o.append("The thesis's images per cell: %s. Ours: the column above. What a cell's count can show: %s.\n" % (
        THESIS_N_TEXT, resolution_text(res) or "no table experiment"))
    return o


def settings_lines(res, e):
    """The settings of an experiment, one markdown list item per scene set and one for the rest."""
    ex = res[e].exp
    lines = []
    if ex.get("settings", {}):
        lines.append("- all scenes: `%s`" % compact(ex["settings"]))
    for s in ex["scenes"]:
        extra = ", ".join("%s %s" % (k, json.dumps(v)) for k, v in s.get("generator", {}).items() if k != "images")
        lines.append("- **%s** (%s, `%s`%s): refinement %s%s" % (
            s["name"], s["scenario"], s["generate"] or s["dataset"], ", " + extra if extra else "",
            "/".join(s.get("refinements") or ex.get("refinements", [])),
            ("; `%s`" % compact(s["settings"])) if s.get("settings") else ""))
    if ex.get("registration_only"):
        info = "registration only from the ground truth perturbed by %g deg and %g mm" % tuple(ex.get("perturb", [0, 0]))
    else:
        info = "descriptors %s" % ", ".join(ex.get("descriptors", []))
    lines.append("- %s; refinements %s; added noise %s mm; grid %s; thresholds (table, warehouse, rotation) %s" % (
        info, ", ".join(ex.get("refinements", [])), ex.get("added_noise_mm"), json.dumps(ex.get("grid", [])),
        ex.get("thresholds")))
    return lines


def settings_block(res, e):
    return ["Settings (`configs/thesis/%s.yaml`):\n" % e, "\n".join(settings_lines(res, e)) + "\n"]


ROBUSTNESS_ROWS = {"robustness": "robustness", "robustness, judged by faces": "robustness_faces"}


def table_md(res, e, cells=()):
    """report.md without its title, its table headings one level down, each
    robustness cell rewritten from `cells` (count, interval, the thesis's value, mark)."""
    lookup = {(c.scenario, c.measure, c.method): c for c in cells if c.experiment == e and c.counted}
    out, methods, scene = [], [], ""
    md = res[e].md.splitlines()
    if md and md[0].startswith("# "):
        md = md[1:]
    for line in md:
        parts = line.split("|")
        if line.startswith("| scenario | measure |"):
            methods, scene = [p.strip() for p in parts[3:-1]], ""
        elif line.startswith("|") and methods and len(parts) == len(methods) + 4 and not line.startswith("|---"):
            scene = parts[1].strip() or scene
            measure = ROBUSTNESS_ROWS.get(parts[2].strip())
            if measure:
                new = [lookup.get((scene, measure, m)) for m in methods]
                line = "|".join(parts[:3] + [" %s " % fmt_rob(c) if c else p for c, p in zip(new, parts[3:-1])] +
                                [parts[-1]])
        elif not line.startswith("|"):
            methods = []
        out.append(line.replace("### ", "#### ", 1) if line.startswith("### ") else line)
    return "\n".join(out).strip() + "\n"


def carton_counts(records):
    """Per (scene, descriptor): [trials, correct (the model's symmetries),
    correct faces on faces (judgements.faces)]; and whether the records are
    judged the thesis's way (every record with an estimate and a ground truth
    carries judgements.faces; older records do not)."""
    counts, judged = {}, True
    for r in records:
        c = counts.setdefault((r["scene"], r["descriptor"]), [0, 0, 0])
        faces = r.get("judgements", {}).get("faces")
        c[0] += 1
        c[1] += 1 if r.get("correct") else 0
        c[2] += 1 if faces and faces["correct"] else 0
        if faces is None and "estimate" in r and "gt" in r:
            judged = False
    return counts, judged


def carton_rows(res, e):
    """The carton's table judged both ways, two rows per scene set."""
    counts, judged = carton_counts(res[e].records)
    descs = res[e].exp["descriptors"]

    def share(s, d, i):
        return "%.0f%%" % (100 * counts[(s, d)][i] / counts[(s, d)][0])

    o = ["| scenario | judgment | " + " | ".join(descs) + " |", "|---|---|" + "---|" * len(descs)]
    for s in res.scenes_of(e):
        o.append("| %s | half turn only | " % s + " | ".join(
            share(s, d, 1) if (s, d) in counts else "-" for d in descs) + " |")
        o.append("|  | faces on faces (thesis) | " + " | ".join(
            "%s (%s)" % (share(s, d, 2), pct(res.thesis(e, s, "robustness", d))) if (s, d) in counts and judged
            else "-" for d in descs) + " |")
    return o, judged


def carton_section(res, e):
    rows, judged = carton_rows(res, e)
    o = ["\nThe carton's symmetries in `models/models.yaml` are only the half turn about its vertical axis (the "
         "gable ridge), and the table above is judged with them: a carton found upside down or turned by 90 "
         "degrees is wrong. The thesis counted the carton correct \"when its faces lie on the true object's "
         "faces, even upside down\". Judged that way (any of the 8 rotations mapping the 70 x 70 x 195 mm body "
         "onto itself, about the body's centre; same 50 mm / 0.05 thresholds), from the same records:\n"] + rows
    if not judged:
        o.append("\nThese records carry no `judgements.faces` (made before that judgement existed): re-run table_4_5 "
                 "(remove `results/thesis/raw/table_4_5`, then `scripts/thesis.sh --only table_4_5`).")
    return o + [""]


def spread(values):
    """(population std, mean, max) of a list, or None when empty."""
    return (statistics.pstdev(values), statistics.fmean(values), max(values)) if values else None


def registration_accuracy(res, e):
    """Table 4.9's accuracy as the thesis defines it (section 4.1.2: the
    standard deviation of the errors over the correctly converged trials),
    the mean (its section 4.2.2 says "averages") and the largest beside it."""
    recs = thesis_protocol("4.9", res[e].records)
    images = {(r["scene"], r["scene_id"], r["im_id"]) for r in recs}
    parts = []
    for m in res[e].exp["refinements"]:
        ok = [r for r in recs if r["refinement"] == m and r.get("correct") and "errors" in r]
        t = spread([r["errors"]["translation_mm"] for r in ok])
        q = spread([r["errors"]["rotation_1mpq"] for r in ok])
        if t and q:
            parts.append("%s (%d correct): translation std %.2f mm (mean %.2f, max %.2f), rotation std %.2g (mean "
                         "%.2g, max %.2g)" % (m, len(ok), t[0], t[1], t[2], q[0], q[1], q[2]))
    return ["\nAccuracy as the thesis defines it: the standard deviation of the errors over the correct trials "
            "(its section 4.1.2; section 4.2.2 calls the table's values averages, so the mean and the largest error "
            "are given too; one trial near the threshold can set the std). Over the %d images where at least one "
            "method is correct, as the thesis counted (its robustness cells above use the same images): %s. Why "
            "ICP point-to-plane is the most accurate here and the least in the thesis: `results/thesis/FINDINGS.md` "
            "(reciprocal correspondences).\n" % (len(images), "; ".join(parts))]


def registration_times(res, e):
    meth = res[e].exp["refinements"]
    rt = {m: mean([r.get("times", {}).get("refine") for r in res[e].records if r["refinement"] == m]) for m in meth}
    return ["\nThe time row above is the whole call (scene preprocessing included); the registration alone took "
            "on average: " + ", ".join("%s %.3f s" % (m, rt[m]) for m in meth if rt[m] is not None) +
            " (the thesis: 0.02 to 0.09 s).\n"]


def table_section(res, e, cells):
    o = ["### %s\n" % TITLES[e]]
    o += settings_block(res, e) + [table_md(res, e, cells)]
    if e == "table_4_5":
        o += carton_section(res, e)
    if e == "table_4_9":
        o += registration_accuracy(res, e) + registration_times(res, e)
    return o + [""]


def section_tables(res, cells):
    o = ["## Tables\n",
         "Rows: scene set x measure; columns: descriptor (refinement for Table 4.9). Robustness = fraction of images "
         "where the chosen pose is correct (translation error < 50 mm on tables, < 100 mm in the warehouse, and "
         "1 - |p.q| < 0.05, symmetry-aware); errors are means over the correct trials; time is the mean online time "
         "per image (s). BOP AR is the BOP average recall (VSD, MSSD, MSPD) of the same poses. Scene sets named "
         "`table_astra` / `table_kinect_one` use the simulated Astra / Kinect One sensors (the thesis's real "
         "sensors).\n", legend(cells)]
    for e in TABLES:
        if e in res:
            o += table_section(res, e, cells)
    return o


# ---- figures ----------------------------------------------------------------------


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
    plot_py = os.path.join(os.path.dirname(os.path.abspath(__file__)), "plot.py")
    subprocess.run([PLOT_PYTHON, plot_py, path, res.plots], check=True, capture_output=True)
    return name + ".png"


def series_rows(plot):
    """One plot's series as a table: robustness (/ mean time) per x value."""
    xs = sorted({x for s in plot["series"] for x in s["x"]})
    o = ["| %s | " % plot["x_label"] + " | ".join("%g" % x for x in xs) + " |", "|---|" + "---|" * len(xs)]
    for s in plot["series"]:
        rob, tm = dict(zip(s["x"], s["robustness"])), dict(zip(s["x"], s["time"]))
        o.append("| %s | " % s["label"] + " | ".join(
            ("%s / %.1fs" % (pct(rob[x]), tm[x]) if tm.get(x) is not None else pct(rob[x])) if x in rob else "-"
            for x in xs) + " |")
    return o + [""]


def series_table(res, parts):
    return "\n".join(line for p in parts if p in res for pl in res[p].plots for line in series_rows(pl))


FIGS = [("fig_4_6", ["fig_4_6"], "Figure 4.6: LS5, CVFH and CESF, CRH skipped: robustness and time vs hypotheses",
         "the thesis's Figure 4.6 pooled the occluded and non-occluded real-sensor scenes and left ESF out; here the "
         "non-occluded Astra and Kinect One sets are plotted"),
        ("fig_4_7", ["fig_4_7_global", "fig_4_7_local"], "Figure 4.7: LS5 robustness vs added noise",
         "the thesis reports that in most scenarios the system did better with some added noise (about 2 mm) than "
         "with none, and that the global descriptors were more robust against noise than the local ones (its "
         "section 5.1); both are checked in the conclusions below. The global descriptors use the thesis's one side "
         "view (0 degrees); in the table scenes, seen from 30-70 degrees above, that view matches poorly (see the "
         "Table 4.3 / 4.4 variants), which keeps the global table curves low"),
        ("fig_4_11", ["fig_4_11_global", "fig_4_11_local"], "Figure 4.11: statue robustness vs added noise",
         "the scenes with 5 mm voxels (statue, table) get much slower with noise: noisy depth fills many more "
         "voxels, so more keypoints and descriptors"),
        ("fig_4_12", ["fig_4_12"], "Figure 4.12: registration robustness vs added noise",
         "registration starts from the ground truth perturbed by the config's perturb_deg / perturb_mm (as Table "
         "4.9), not from recognition hypotheses")]


def figure_section(res, name, have, title, note):
    o = ["### %s\n" % title]
    for p in have:
        o += settings_block(res, p)
    png = merged_plot(res, name, have, title) if len(have) > 1 else None
    if png is None:
        pl = res[have[0]].plots
        png = "%s_%s.png" % (have[0], pl[0]["name"]) if pl else None
    if png:
        o.append("![%s](plots/%s)\n" % (title, png))
    o += ["Robustness (and mean time per image) per series and x value:\n", series_table(res, have)]
    if note:
        o.append("Note: %s.\n" % note)
    return o


def section_figures(res):
    o = ["## Figures\n"]
    for name, parts, title, note in FIGS:
        have = [p for p in parts if p in res]
        if have:
            o += figure_section(res, name, have, title, note)
    return o


# ---- cells: counts per table cell, against the thesis -------------------------------

MAIN_TABLES = collections.OrderedDict([("table_4_1", "4.1"), ("table_4_3", "4.3"), ("table_4_4", "4.4"),
                                       ("table_4_5", "4.5"), ("table_4_7", "4.7"), ("table_4_9", "4.9")])
MAIN_CELLS = 107  # robustness values of the thesis's Tables 4.1, 4.3, 4.4, 4.5, 4.7 and 4.9
POINTS = 15       # "within 15 points" of the thesis
FACES = "robustness_faces"
CSV_COLUMNS = ["table", "experiment", "kind", "scenario", "measure", "method", "ours_k", "n", "ours", "wilson_lo",
               "wilson_hi", "thesis", "thesis_n", "thesis_k", "thesis_exact", "p_value", "within_15",
               "significant_05", "significant_01"]
THESIS_N_TEXT = ("30 per synthetic scene set (warehouse_synthetic, table_synthetic), 60 per simulated-sensor scene set "
                 "(table_astra, table_kinect_one; the thesis's real sensors), 20 per occluded one (table_*_occluded), "
                 "19 in Table 4.9 (its 95/84/100% imply n = 19)")


def thesis_images(table, scenario):
    """The thesis's images per cell (THESIS.md), None when it says none for this scene set."""
    if table == "4.9":
        return 19
    if scenario.endswith("_occluded"):
        return 20
    if scenario in ("table_astra", "table_kinect_one"):
        return 60
    if scenario in ("warehouse_synthetic", "table_synthetic"):
        return 30
    return None


class Cell:
    """One cell of a table experiment: a robustness (ours k of n against the
    thesis's value, its k of its n) or a time (mean seconds; no counts)."""

    def __init__(self, table, experiment, kind, scenario, measure, method, k=None, n=None, ours=None, thesis=None,
                 thesis_n=None):
        self.table, self.experiment, self.kind = table, experiment, kind
        self.scenario, self.measure, self.method = scenario, measure, method
        self.k, self.n, self.thesis, self.thesis_n = k, n, thesis, thesis_n
        self.ours = k / n if k is not None and n else ours
        counted = k is not None and n
        self.lo, self.hi = wilson(k, n) if counted else (None, None)
        self.thesis_k = count_of(thesis, thesis_n) if counted and thesis is not None and thesis_n else None
        self.exact = printable_as_count(thesis, thesis_n) if self.thesis_k is not None else None
        self.p = fisher_exact(k, n, self.thesis_k, thesis_n) if self.thesis_k is not None else None
        self.within = (within_points(self.ours, thesis, POINTS) if counted and thesis is not None else None)

    @property
    def counted(self):
        return self.k is not None

    @property
    def main(self):
        """One of the thesis's 107 robustness cells."""
        return self.kind == "main" and self.measure == "robustness"

    def mark(self):
        return "" if self.p is None else (" **" if self.p < 0.01 else (" *" if self.p < 0.05 else ""))

    def csv_row(self):
        def f(v, fmt="%.6g"):
            return "" if v is None else (str(v).lower() if isinstance(v, bool) else fmt % v)
        return [self.table, self.experiment, self.kind, self.scenario, self.measure, self.method, f(self.k, "%d"),
                f(self.n, "%d"), f(self.ours), f(self.lo, "%.4f"), f(self.hi, "%.4f"), f(self.thesis),
                f(self.thesis_n, "%d"), f(self.thesis_k, "%d"), f(self.exact), f(self.p, "%.4g"), f(self.within),
                f(None if self.p is None else self.p < 0.05), f(None if self.p is None else self.p < 0.01)]


def method_column(exp):
    """The record key a table's columns are: refinement (registration tables) or descriptor."""
    return "refinement" if exp.get("report", {}).get("columns") == "refinement" else "descriptor"


def condition_of(r):
    """A record's condition: its added noise and swept parameters."""
    return (float(r["added_noise_mm"]), json.dumps(r["params"], sort_keys=True))


def condition_label(cond):
    noise, params = cond
    p = json.loads(params)
    return ", ".join(["noise %g mm" % noise] + ["%s %s" % (k, json.dumps(v)) for k, v in sorted(p.items())])


def experiment_json(res, x):
    if not x.exp:
        raise InputError("%s: missing or empty" % os.path.join(res.raw, x.name, "experiment.json"))
    for key in ("scenes", "descriptors", "refinements"):
        if key not in x.exp:
            raise InputError("%s: no '%s'" % (os.path.join(res.raw, x.name, "experiment.json"), key))
    return x.exp


def group_records(res, x):
    """{(scene, method, condition label): records} of an experiment, in its
    config's order (scenes, then methods, then conditions); the label is ""
    when all records share one condition."""
    exp = experiment_json(res, x)
    col = method_column(exp)
    conds = sorted({condition_of(r) for r in x.records})
    single = len(conds) <= 1
    order = {s["name"]: i for i, s in enumerate(exp["scenes"])}
    meths = {m: i for i, m in enumerate(exp["refinements"] if col == "refinement" else exp["descriptors"])}
    groups = {}
    for r in x.records:
        c = condition_of(r)
        groups.setdefault((r["scene"], r[col], "" if single else condition_label(c)), (c, []))[1].append(r)
    keys = sorted(groups, key=lambda k: (order.get(k[0], len(order)), k[0], meths.get(k[1], len(meths)), k[1],
                                         groups[k][0]))
    return collections.OrderedDict((k, groups[k][1]) for k in keys)


def n_correct(records, faces=False):
    if faces:
        return sum(1 for r in records if r.get("judgements", {}).get("faces", {}).get("correct"))
    return sum(1 for r in records if r.get("correct"))


def thesis_values(res, x):
    """{(scenario, measure, method): thesis value or None} of report.csv's unconditioned rows."""
    path = os.path.join(res.raw, x.name, "report.csv")
    if not x.rows:
        raise InputError("%s: missing or empty; the thesis's values beside the cells come from it (run `posebench "
                         "report %s --format md,csv`)" % (path, os.path.join(res.raw, x.name)))
    out = {}
    for i, r in enumerate(x.rows, 2):
        missing = [c for c in ("condition", "scenario", "measure", "method", "thesis") if r.get(c) is None]
        if missing:
            raise InputError("%s: line %d: no column '%s'" % (path, i, missing[0]))
        if r["condition"] != "":
            continue
        try:
            out[(r["scenario"], r["measure"], r["method"])] = float(r["thesis"]) if r["thesis"] != "" else None
        except ValueError:
            raise InputError("%s: line %d: field 'thesis' is not a number: %r" % (path, i, r["thesis"])) from None
    return out


def table_of(x):
    return (x.exp or {}).get("report", {}).get("reference_table")


def thesis_protocol(table, records):
    """The records a table counts as the thesis did: for Table 4.9 only the
    images where at least one registration method is correct ("Only these
    depth images for which at least one of the registration methods could
    align the model to a correct solution was used"); every record otherwise."""
    if table != "4.9":
        return records
    ok = {(r["scene"], r["scene_id"], r["im_id"]) for r in records if r.get("correct")}
    return [r for r in records if (r["scene"], r["scene_id"], r["im_id"]) in ok]


def table_cells(res, x, kind, ref):
    """The cells of a table experiment: robustness (and for the milk carton,
    judged faces on faces when every record is), then time; the thesis's
    values from `ref`'s report.csv (the experiment itself, or the one an
    ablation is paired with)."""
    table = table_of(x) or table_of(ref)
    x = Experiment(x.name, x.exp, thesis_protocol(table, x.records), x.md, x.rows, x.plots, x.runs)
    groups = group_records(res, x)
    if any(c for _s, _m, c in groups):
        raise InputError("%s: records of several conditions (added_noise_mm, params); a table experiment has one" %
                         os.path.join(res.raw, x.name, "records.jsonl"))
    tv = thesis_values(res, ref)
    path = os.path.join(res.raw, ref.name, "report.csv")
    faces = table == "4.5" and carton_counts(x.records)[1]
    rob, face, times = [], [], []
    for (s, m, _c), recs in groups.items():
        th = tv.get((s, "robustness", m))
        if th is None:
            raise InputError("%s: no thesis value (field 'thesis') for scenario %s, measure robustness, method %s" %
                             (path, s, m))
        tn = thesis_images(table, s)
        if tn is None:
            raise InputError("%s: scenario %s: the thesis's number of images is not known for this scene set "
                             "(thesis_images in scripts/thesis_report.py)" % (
                                 os.path.join(res.raw, x.name, "records.jsonl"), s))
        rob.append(Cell(table, x.name, kind, s, "robustness", m, n_correct(recs), len(recs), thesis=th, thesis_n=tn))
        if faces:
            face.append(Cell(table, x.name, kind, s, FACES, m, n_correct(recs, True), len(recs), thesis=th,
                             thesis_n=tn))
        t = mean([r["times"]["total"] for r in recs if "times" in r])
        times.append(Cell(table, x.name, kind, s, "time", m, ours=t, thesis=tv.get((s, "time", m))))
    return rob + face + times


def all_cells(res):
    """Every table experiment's cells: main tables, variants, then ablations."""
    cells = []
    for e, x in res.x.items():
        ablated = e in res.ablation_only
        ref = res.x.get(res.partner.get(e)) if ablated else x
        if ref is None or not (table_of(x) or table_of(ref)):
            continue
        kind = "ablation" if ablated else ("main" if e in MAIN_TABLES else "variant")
        cells += table_cells(res, x, kind, ref)
    order = {"main": 0, "variant": 1, "ablation": 2}
    return sorted(cells, key=lambda c: order[c.kind])  # stable: experiments keep their order


def write_cells_csv(path, cells):
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(CSV_COLUMNS)
        for c in cells:
            w.writerow(c.csv_row())


def fmt_rob(c):
    """`70% 7/10 [39-89] (35%) *`: ours, k/n, 95% Wilson interval, the thesis's value, Fisher's mark."""
    return "%s %d/%d [%.0f-%.0f] (%s)%s" % (pct(c.ours), c.k, c.n, 100 * c.lo, 100 * c.hi, pct(c.thesis), c.mark())


def legend(cells):
    return ("Robustness cells read `70%% 7/10 [39-89] (35%%) *`: our fraction correct, the count k/n from the "
            "records, its 95%% Wilson interval (%%), the thesis's value in parentheses, and a mark when Fisher's exact "
            "test (two-sided) of our k/n against the thesis's k/n is significant: `*` p < 0.05, `**` p < 0.01. The "
            "thesis's n per cell: %s; its k = round(value x n). %s\n" % (THESIS_N_TEXT, sample_sizes_text(cells)))


def sample_sizes_text(cells):
    """Our trials per cell, per experiment (from the records)."""
    per = collections.OrderedDict()
    for c in cells:
        if c.counted and c.measure == "robustness":
            per.setdefault(c.experiment, set()).add(c.n)
    return "Our n per cell (trials, from the records): " + "; ".join(
        "%s %s" % (e, "-".join(str(v) for v in sorted({min(ns), max(ns)}))) for e, ns in per.items()) + "."


def inexact_text(cells):
    """The thesis's values that are no k/n at the n assumed (a percentage
    rounded to whole), and per row the largest n they all fit."""
    bad = [c for c in cells if c.main and c.exact is False]
    if not bad:
        return "Every thesis value here is some k/n at the n assumed."
    rows = collections.OrderedDict()
    for c in bad:
        rows.setdefault((c.table, c.experiment, c.scenario, c.thesis_n), []).append(c)
    fits = []
    for (t, e, s, n), row_bad in rows.items():
        m = fitting_n([c.thesis for c in cells if c.main and (c.experiment, c.scenario) == (e, s)], n)
        fits.append("Table %s %s (n %d): %s; %s" % (
            t, s, n, ", ".join("%s %s" % (c.method, pct(c.thesis)) for c in row_bad),
            "the row's values all fit n = %d" % m if m else "the row's values fit no n from %d to %d" % (n // 2, n)))
    return ("%d of the thesis's %d values cannot be k/n at the n assumed (whole percent): %s. Those scene sets "
            "probably had fewer usable images than the thesis states; k is round(value x n) all the same, so the "
            "test is approximate there." % (len(bad), len([c for c in cells if c.main]), "; ".join(fits)))


def direction_text(cells):
    """Of the main cells outside 15 points, how many lie above the thesis's
    value and how many below, per method: which way the gaps go."""
    out = [c for c in cells if c.main and c.within is False]
    if not out:
        return ""
    above = [c for c in out if c.ours > c.thesis]
    per = collections.OrderedDict()
    for c in out:
        per.setdefault(c.method, [0, 0])[0 if c.ours > c.thesis else 1] += 1
    return ("Which way the gaps go: of the %d cells outside 15 points, %d are above the thesis's value (ours more "
            "robust) and %d below; per method (above / below): %s." % (
                len(out), len(above), len(out) - len(above),
                ", ".join("%s %d / %d" % (m, a, b) for m, (a, b) in per.items())))


# ---- the scorecard -----------------------------------------------------------------------

def rows_of(cells):
    """Cells grouped by (experiment, scenario, measure), in order."""
    rows = collections.OrderedDict()
    for c in cells:
        rows.setdefault((c.experiment, c.scenario, c.measure), []).append(c)
    return list(rows.values())


def best_set(values):
    top = max(values)
    return {i for i, v in enumerate(values) if v >= top - 1e-12}


def best_agrees(row):
    """Some method is most robust (ties included) both here and in the thesis."""
    return bool(best_set([c.ours for c in row]) & best_set([c.thesis for c in row]))


def tau_positive(row):
    """Kendall's tau-b of our values against the thesis's above 0 (undefined: not)."""
    t = kendall_tau([c.ours for c in row], [c.thesis for c in row])
    return t is not None and t > 0


def score(cells):
    rows = [r for r in rows_of(cells) if len(r) > 1]
    return collections.OrderedDict([
        ("cells", len(cells)),
        ("within_15", sum(1 for c in cells if c.within)),
        ("significant_05", sum(1 for c in cells if c.p < 0.05)),
        ("significant_01", sum(1 for c in cells if c.p < 0.01)),
        ("rows", len(rows)),
        ("best_agrees", sum(1 for r in rows if best_agrees(r))),
        ("tau_positive", sum(1 for r in rows if tau_positive(r))),
        ("mean_ours", round(mean([c.ours for c in cells]), 4) if cells else None),
        ("mean_thesis", round(mean([c.thesis for c in cells]), 4) if cells else None)])


def scorecard(cells):
    """The agreement counts per main table, in total, and per variant."""
    main = [c for c in cells if c.main]
    tables = []
    for e, t in MAIN_TABLES.items():
        mine = [c for c in main if c.experiment == e]
        if mine:
            tables.append(collections.OrderedDict([("table", t), ("experiment", e)] + list(score(mine).items())))
    variants = []
    for key in collections.OrderedDict(((c.experiment, c.measure), None) for c in cells if c.counted and not c.main
                                       and c.kind != "ablation"):
        mine = [c for c in cells if (c.experiment, c.measure) == key]
        variants.append(collections.OrderedDict([("table", mine[0].table), ("experiment", key[0]),
                                                 ("measure", key[1])] + list(score(mine).items())))
    total = collections.OrderedDict([("of", MAIN_CELLS)] + list(score(main).items()))
    return collections.OrderedDict([
        ("rules", collections.OrderedDict([
            ("within_15", "|ours - thesis| <= 15 percentage points"),
            ("significant", "Fisher's exact test, two-sided, ours k/n against the thesis's round(value x n)/n"),
            ("thesis_n", THESIS_N_TEXT),
            ("best_agrees", "a row agrees when some method is most robust (ties included) both in ours and in the "
                            "thesis's"),
            ("tau_positive", "Kendall's tau-b of a row's values against the thesis's is above 0 (undefined, a row "
                             "all tied: not)")])),
        ("tables", tables), ("total", total), ("variants", variants)])


SCORECARD_BEFORE = "scorecard_before.json"
BEFORE_TEXT = (
    "The line \"before issue 10\" is the same scorecard of the run before the set-up changes (`%s` beside this "
    "README: 10 images per cell, training views at 0 and 20 degrees, a floor and a wall in the warehouse, the "
    "Astra before its calibration, occluded targets 40-90%% visible, CESF without its fallback).")


def scorecard_before(res):
    """The totals of OUT/scorecard_before.json (the run before issue 10's set-up changes), or None."""
    path = os.path.join(os.path.dirname(res.raw.rstrip(os.sep)), SCORECARD_BEFORE)
    try:
        with open(path) as f:
            total = json.load(f)["total"]
        return total if all(k in total for k in ("cells", "within_15", "significant_05", "significant_01", "rows",
                                                  "best_agrees", "tau_positive", "mean_ours", "mean_thesis")) else None
    except (OSError, ValueError, KeyError, TypeError):
        return None


def section_agreement(res, cells, card):
    if not card["tables"] and not card["variants"]:
        return []
    o = ["## Agreement with the thesis\n",
         "Robustness cells of the thesis's Tables 4.1, 4.3, 4.4, 4.5, 4.7 and 4.9 (%d values; the milk carton judged "
         "with the model's symmetries, as its table above), computed from the records. Within 15: |ours - thesis| "
         "<= 15 points. p: Fisher's exact test (two-sided) of our k/n against the thesis's k/n (its n: %s; k = "
         "round(value x n)). Best agrees: some method is the most robust, ties included, both here and in the "
         "thesis's row. tau > 0: Kendall's tau-b of the row's values against the thesis's is positive (a row all "
         "tied on one side has none and does not count). `--scorecard-json FILE` prints these numbers as JSON.\n" %
         (MAIN_CELLS, THESIS_N_TEXT),
         "| table | cells | within 15 points | p < 0.05 | p < 0.01 | rows | best agrees | tau > 0 | mean, ours | "
         "mean, thesis |", "|---|---|---|---|---|---|---|---|---|---|"]

    def line(name, s):
        return "| %s | %d | %d | %d | %d | %d | %d | %d | %s | %s |" % (
            name, s["cells"], s["within_15"], s["significant_05"], s["significant_01"], s["rows"], s["best_agrees"],
            s["tau_positive"], pct(s["mean_ours"]), pct(s["mean_thesis"]))
    o += [line("Table " + t["table"], t) for t in card["tables"]]
    t = card["total"]
    if t["cells"]:
        o.append(line("**total** (of the thesis's %d)" % t["of"], t))
    before = scorecard_before(res)
    if before and t["cells"]:
        o.append(line("total before issue 10 (`%s`)" % os.path.basename(SCORECARD_BEFORE), before))
    if card["variants"]:
        o += ["", "Not counted above (the same comparison, against the thesis's values of the table named):\n",
              "| variant | cells | within 15 points | p < 0.05 | p < 0.01 | rows | best agrees | tau > 0 | mean, ours "
              "| mean, thesis |", "|---|---|---|---|---|---|---|---|---|---|"]
        o += [line("Table %s: %s%s" % (v["table"], v["experiment"], ", judged faces on faces (the thesis's "
                                       "judgement)" if v["measure"] == FACES else ""), v) for v in card["variants"]]
    o += ["", inexact_text(cells), ""]
    if direction_text(cells):
        o += [direction_text(cells), ""]
    if scorecard_before(res) and t["cells"]:
        o += [BEFORE_TEXT % SCORECARD_BEFORE, ""]
    return o


# ---- the thesis's conclusions ---------------------------------------------------------


def accuracy_of(records):
    ok = [r for r in records if r.get("correct") and "errors" in r]
    return (mean([r["errors"]["translation_mm"] for r in ok]), mean([r["errors"]["rotation_1mpq"] for r in ok]))


def figure_curves(res):
    """thesis_verdicts.Curve per (figure experiment, scene, method): correct,
    trials and mean time per x value (the experiment's report.plot_x)."""
    curves = []
    for e, x in res.x.items():
        if e in res.ablation_only or table_of(x) or not x.exp:
            continue
        plot_x = x.exp.get("report", {}).get("plot_x", "added_noise_mm")
        col = method_column(experiment_json(res, x))
        pts = collections.OrderedDict()
        for n, r in enumerate(x.records, 1):
            if plot_x == "added_noise_mm":
                xv = float(r["added_noise_mm"])
            elif plot_x in r["params"]:
                xv = r["params"][plot_x]
            else:
                raise InputError("%s: line %d: no params.%s (the experiment's report.plot_x)" % (
                    os.path.join(res.raw, e, "records.jsonl"), n, plot_x))
            pts.setdefault((r["scene"], r[col]), {}).setdefault(xv, []).append(r)
        for (s, m), by_x in pts.items():
            curves.append(Curve(e, s, m, collections.OrderedDict(
                (xv, (n_correct(rs), len(rs), mean([r["times"]["total"] for r in rs if "times" in r])))
                for xv, rs in sorted(by_x.items()))))
    return curves


def verdict_data(res, cells):
    """Our numbers as the rules read them (main tables, variants, figures)."""
    mine = [c for c in cells if c.kind != "ablation"]
    acc = {}
    for c in mine:
        if c.measure == "robustness" and c.table == "4.9":
            recs = [r for r in res[c.experiment].records if r["scene"] == c.scenario and
                    r[method_column(res[c.experiment].exp)] == c.method]
            acc[(c.experiment, c.scenario, c.method)] = accuracy_of(recs)
    return Data(rob=collections.OrderedDict(((c.experiment, c.scenario, c.method), (c.k, c.n)) for c in mine
                                            if c.measure == "robustness"),
                time={(c.experiment, c.scenario, c.method): c.ours for c in mine if c.measure == "time"},
                accuracy=acc, curves=figure_curves(res),
                registration_only={e for e, x in res.x.items() if (x.exp or {}).get("registration_only")})


def thesis_data(res, cells):
    """The thesis's own numbers as the rules read them (its tables; it printed no numbers for its figures)."""
    main = [c for c in cells if c.kind == "main"]
    acc = {}
    for c in main:
        if c.measure == "robustness" and c.table == "4.9":
            acc[(c.experiment, c.scenario, c.method)] = (res.thesis(c.experiment, c.scenario, "translation_mm",
                                                                    c.method),
                                                         res.thesis(c.experiment, c.scenario, "rotation_1mpq",
                                                                    c.method))
    return Data(rob=collections.OrderedDict(((c.experiment, c.scenario, c.method), (c.thesis_k, c.thesis_n))
                                            for c in main if c.measure == "robustness"),
                time={(c.experiment, c.scenario, c.method): c.thesis for c in main if c.measure == "time"},
                accuracy=acc, registration_only={"table_4_9"})


def verdicts(res, cells):
    """[(id, title, rule, ours, thesis's)] of the seven conclusions."""
    theirs = {cid: v for cid, _t, _r, v in evaluate(thesis_data(res, cells))}
    return [(cid, title, rule, v, theirs[cid]) for cid, title, rule, v in evaluate(verdict_data(res, cells))]


def section_conclusions(res, cells):
    found = [v for v in verdicts(res, cells) if v[3] is not None]
    if not found:
        return []
    o = ["## The thesis's conclusions against these numbers\n",
         "Each verdict is computed by `scripts/thesis_verdicts.py` from the records, by a rule written down before "
         "the run; the rule is printed before its evidence. The same rule applied to the thesis's own table values "
         "(k = round(value x n) at its n; it printed no numbers for its figures) is given after it, as a check of "
         "the rule.\n"]
    for cid, title, rule, v, theirs in found:
        o.append("**%s. %s: %s.**\n" % (cid, title, v.word))
        o.append("- Rule: %s" % rule)
        o.append("- Here: %s" % v.evidence)
        o.append("- On the thesis's own numbers: %s\n" % (
            "%s. %s" % (theirs.word, theirs.evidence) if theirs else "no numbers (figures only)."))
    return o


# ---- ablations -----------------------------------------------------------------------------

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ABLATIONS = os.path.join(ROOT, "configs", "thesis", "ablations.yaml")


def shown_path(path):
    """A path as the README shows it: relative to the source root when inside it."""
    a = os.path.abspath(path)
    return os.path.relpath(a, ROOT) if a.startswith(ROOT + os.sep) else path


def load_ablations(path):
    """The ablations of a file (scripts/thesis_ablations.py's schema), each
    with its `pairs` [experiment as reported, its ablation copy]; [] without
    a file. InputError naming the file and field on a bad one."""
    if not path or not os.path.exists(path):
        return []
    try:
        ablations = thesis_ablations.load_spec(path)
    except thesis_ablations.SpecError as e:
        raise InputError(str(e)) from None
    return [dict(a, pairs=[[e, thesis_ablations.ablation_name(a["name"], e)] for e in a["experiments"]])
            for a in ablations]


def counts_of(res, e):
    """{(scene, method, condition): (k, n)} of an experiment's records."""
    return collections.OrderedDict((key, (n_correct(recs), len(recs)))
                                   for key, recs in group_records(res, res[e]).items())


class Moved:
    """One cell of an ablation pair: as reported (k, n) and with the cause switched back (k2, n2)."""

    def __init__(self, e, e2, key, kn, kn2, thesis):
        self.e, self.e2, (self.scenario, self.method, self.cond) = e, e2, key
        (self.k, self.n), (self.k2, self.n2), self.thesis = kn, kn2, thesis
        self.a, self.b = self.k / self.n, self.k2 / self.n2
        self.p = fisher_exact(self.k, self.n, self.k2, self.n2)
        self.moved = not within_points(self.a, self.b, POINTS)


def ablation_cells(res, ablation, thesis):
    """(compared cells, skipped pairs) of an ablation; thesis: {(experiment, scene, method): value}."""
    compared, skipped = [], []
    for e, e2 in ablation["pairs"]:
        missing = [x for x in (e, e2) if x not in res]
        if missing:
            skipped.append((e, e2, missing))
            continue
        a, b = counts_of(res, e), counts_of(res, e2)
        for key in a:
            if key in b and a[key][1] and b[key][1]:
                compared.append(Moved(e, e2, key, a[key], b[key],
                                      thesis.get((e, key[0], key[1])) if not key[2] else None))
    return compared, skipped


def explains(m, cell):
    """Whether an ablation's cell m explains the gap of a main cell: switching
    the cause closes at least half the gap, at p < 0.05. The switched value
    must lie within half the gap of the thesis's value, so a cell that moves
    toward the thesis and far past it (77% -> 7% against 60%) is not
    explained."""
    gap, effect = cell.thesis - cell.ours, m.b - m.a
    return gap * effect > 0 and abs(cell.thesis - m.b) <= abs(gap) / 2 + 1e-12 and m.p < 0.05


EXPLAIN_RULE = (
    "A cell of the %d outside 15 points of the thesis is explained by a cause when an ablation of that cause covers "
    "it (a pair whose first experiment is the cell's, with the same scene set and method) and switching the cause "
    "closes at least half the gap: the switched value lies within half the gap (thesis - ours) of the thesis's "
    "value, on either side, the two counts differing at p < 0.05 (Fisher's exact test). A cell that moves toward "
    "the thesis and far past it is not explained.")


def section_ablations(res, ablations, cells, path):
    o = ["## Ablations: what each change of the set-up does\n"]
    if not ablations:
        return o + ["No ablations (`%s` is missing or lists none).\n" % shown_path(path)]
    o.append("Each ablation runs an experiment again with one cause switched back (`%s`): back to the set-up before "
             "issue 10, or to another reading of what the thesis leaves open (the column says which). Per ablation: "
             "the cells "
             "compared, those that move by more than 15 points, those whose two counts differ at p < 0.05 (Fisher's "
             "exact test), the mean robustness both ways and how many cells are within 15 points of the thesis both "
             "ways.\n" % shown_path(path))
    thesis = {(c.experiment, c.scenario, c.method): c.thesis for c in cells if c.measure == "robustness"
              and c.kind != "ablation"}
    by_ablation = []
    rows = ["| ablation | cause | switched back | pairs run | cells | moved > 15 points | p < 0.05 | mean, as reported "
            "| mean, switched back | within 15 of the thesis, as reported | switched back |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    notes = []
    for a in ablations:
        compared, skipped = ablation_cells(res, a, thesis)
        by_ablation.append((a, compared))
        with_t = [m for m in compared if m.thesis is not None]
        rows.append("| %s | %s | %s | %d of %d | %d | %d | %d | %s | %s | %s | %s |" % (
            a["name"], a["cause"], a["switched"], len(a["pairs"]) - len(skipped), len(a["pairs"]), len(compared),
            sum(m.moved for m in compared), sum(m.p < 0.05 for m in compared),
            pct(mean([m.a for m in compared])), pct(mean([m.b for m in compared])),
            "%d of %d" % (sum(within_points(m.a, m.thesis, POINTS) for m in with_t), len(with_t)) if with_t else "-",
            "%d of %d" % (sum(within_points(m.b, m.thesis, POINTS) for m in with_t), len(with_t)) if with_t else "-"))
        for e, e2, missing in skipped:
            notes.append("- %s: pair %s / %s skipped, no records for %s (`results/thesis/raw/NAME/records.jsonl`)." % (
                a["name"], e, e2, ", ".join(missing)))
        moved = [m for m in compared if m.moved]
        if moved:
            notes.append("- %s, cells moved by more than 15 points (scene set, method: as reported -> switched back, "
                         "thesis): %s." % (a["name"], "; ".join(
                             "%s %s %s%s: %d/%d -> %d/%d (%s -> %s, p = %.2g), thesis %s" % (
                                 m.e, m.scenario, m.method, " (%s)" % m.cond if m.cond else "", m.k, m.n, m.k2,
                                 m.n2, pct(m.a), pct(m.b), m.p, pct(m.thesis)) for m in moved)))
    o += rows + [""] + (notes + [""] if notes else [])
    gaps = [c for c in cells if c.main and not c.within]
    o.append("**Which gaps to the thesis the ablations explain.** " + EXPLAIN_RULE % len(gaps) + "\n")
    explained, unexplained = [], []
    for c in gaps:
        by = [a["name"] for a, compared in by_ablation for m in compared
              if (m.e, m.scenario, m.method, m.cond) == (c.experiment, c.scenario, c.method, "") and explains(m, c)]
        (explained if by else unexplained).append((c, by))
    o.append("Of the %d main cells outside 15 points, %d explained (%s), %d unexplained.\n" % (
        len(gaps), len(explained), "; ".join("%s %s %s by %s" % (short_title(c.experiment), c.scenario, c.method,
                                                                 ", ".join(by)) for c, by in explained) or "none",
        len(unexplained)))
    o.append("No correction is made for the %d %s tried: each is judged by the rule on its own, so a cell can pass "
             "it by chance. An ablation that explains one cell can also move others away from the thesis (the "
             "table's cells within 15 points, as reported and switched back). So an explanation shows a set-up "
             "choice that can close the gap, not that the thesis made that choice.\n" % (
                 len(ablations), "ablation" if len(ablations) == 1 else "ablations"))
    if unexplained:
        o.append("Unexplained (ours vs the thesis): " + "; ".join(
            "%s %s %s %s vs %s" % (short_title(c.experiment), c.scenario, c.method, pct(c.ours), pct(c.thesis))
            for c, _ in unexplained) + ".\n")
        chance = [c for c, _ in unexplained if c.p is not None and c.p >= 0.05]
        sig = len(unexplained) - len(chance)
        o.append("Of the %d unexplained, %d %s from the thesis's count at p < 0.05 (Fisher's exact test at the "
                 "thesis's n, as the scorecard) and %d %s not: %s. A gap of the second kind can be chance at these "
                 "sample sizes; it still counts as unexplained.\n" % (
                     len(unexplained), sig, "differs" if sig == 1 else "differ", len(chance),
                     "does" if len(chance) == 1 else "do",
                     "; ".join("%s %s %s %d/%d vs %s (p = %.2g)" % (short_title(c.experiment), c.scenario, c.method,
                                                                    c.k, c.n, pct(c.thesis), c.p)
                               for c in chance) or "none"))
    return o


# ---- the README ---------------------------------------------------------------------


def host_info():
    """Date, CPU model, cores and worker processes, for the README's first lines."""
    cpu = ""
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((l.split(":")[1].strip() for l in f if l.startswith("model name")), "")
    except OSError:
        pass
    return {"date": datetime.date.today().isoformat(), "cpu": cpu, "cores": os.cpu_count(),
            "jobs": os.environ.get("JOBS", "2")}


def readme(res, host, cells, ablations, ablations_path):
    """The README's text."""
    blocks = (section_intro(res, host) + section_reproduce() + section_differences(res) +
              section_experiments(res) + section_tables(res, cells) + section_figures(res) +
              section_agreement(res, cells, scorecard(cells)) + section_conclusions(res, cells) +
              section_ablations(res, ablations, cells, ablations_path))
    return "\n".join(blocks) + "\n"


def scorecard_json(res, cells):
    """The scorecard and the verdicts as one JSON object."""
    card = scorecard(cells)
    card["verdicts"] = collections.OrderedDict(
        (cid, collections.OrderedDict([("ours", v.word if v else None), ("thesis_numbers", t.word if t else None),
                                       ("numbers", v.numbers if v else None)]))
        for cid, _title, _rule, v, t in verdicts(res, cells))
    card["raw"] = os.path.realpath(res.raw)
    return json.dumps(card, indent=1) + "\n"


USAGE_ERROR = 2


def parse_args(argv):
    """(OUT, experiments, {option: value}) of the command line; ValueError on a bad option."""
    opts, rest, i = {}, [], 0
    while i < len(argv):
        a = argv[i]
        if a in ("--scorecard-json", "--ablations"):
            if i + 1 >= len(argv):
                raise ValueError("%s needs a value" % a)
            opts[a], i = argv[i + 1], i + 2
            continue
        if a.startswith("--"):
            raise ValueError("unknown option %s" % a)
        rest.append(a)
        i += 1
    if not rest:
        raise ValueError("no OUT folder")
    return rest[0], rest[1:], opts


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__.strip(), file=sys.stderr)
        return 0 if argv else USAGE_ERROR
    try:
        out_dir, experiments, opts = parse_args(argv)
    except ValueError as err:
        print("thesis_report.py: %s (see --help)" % err, file=sys.stderr)
        return USAGE_ERROR
    binary = os.environ.get("POSEBENCH", "build/posebench")
    schema = schema_from_binary(binary)
    if schema is None and binary and os.path.exists(binary):
        print("thesis_report.py: `%s schema record` gave no schema (a binary from before it?); using the copy in "
              "thesis_report.py" % binary, file=sys.stderr)
    ablations_path = opts.get("--ablations", ABLATIONS)
    try:
        ablations = load_ablations(ablations_path)
        res = load_results(out_dir, experiments, schema or RECORD_SCHEMA, ablations)
        cells = all_cells(res) if res.x else []
        if "--scorecard-json" in opts:
            text = scorecard_json(res, cells)
        elif res.x:
            text = readme(res, host_info(), cells, ablations, ablations_path)
    except InputError as err:
        print("thesis_report.py: %s" % err, file=sys.stderr)
        return 2
    if "--scorecard-json" in opts:
        if opts["--scorecard-json"] == "-":
            sys.stdout.write(text)
        else:
            with open(opts["--scorecard-json"], "w") as f:
                f.write(text)
            print(opts["--scorecard-json"])
        return 0
    path = os.path.join(out_dir, "README.md")
    if not res.x:  # e.g. a fresh clone: keep the committed README rather than empty it
        print("thesis_report.py: no experiment's records.jsonl in %s; %s left as it is" % (res.raw, path),
              file=sys.stderr)
        return 0
    with open(path, "w") as f:
        f.write(text)
    write_cells_csv(os.path.join(out_dir, "cells.csv"), cells)
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
