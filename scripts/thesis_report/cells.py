"""Counts per table cell against the thesis's values, and cells.csv.

A robustness cell is k of n correct from the records, its 95% Wilson interval
and Fisher's exact test against the thesis's k of its n; a time cell is the
mean online time per image.
"""
import collections
import csv
import json
import os

from thesis_stats import count_of, fisher_exact, printable_as_count, wilson, within_points

from .formatting import mean
from .results import Experiment
from .schema import InputError


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
                             "(thesis_images in scripts/thesis_report/cells.py)" % (
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
