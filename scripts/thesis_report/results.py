"""The experiments' folders OUT/raw/NAME: config, records, report and runs."""
import csv
import json
import os

from .runs import Runs, load_folder_runs
from .schema import load_records


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
