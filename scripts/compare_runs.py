#!/usr/bin/env python3
"""Robustness of two runs of the same experiments, cell by cell.

    scripts/compare_runs.py BEFORE AFTER [--json FILE]

BEFORE and AFTER are results folders of `posebench run` (one experiment, with
records.jsonl) or folders holding several of them (e.g. results/thesis/raw).
A cell is (experiment, scene set, object, descriptor, refinement, added
noise, the trial's params; an `object: all` run has a cell per object); its
count is the correct records of k/n. Per cell, Fisher's exact test
(two-sided) of the two counts. Prints the totals (cells, equal, up, down,
p < 0.05), the significant cells, the cells that moved most, and
the worker seconds (records' wall_s) per experiment, and the trials paired
across the runs by experiment and trial key (the same image and seed):
how many are correct in one run only, with McNemar's exact test of the two
runs' robustness over all cells. Records are read with
thesis_report/schema.py's loader (checked against the trial record's
schema). Exit 2, naming the file, line and key, for a record that does not
fit, and for a folder without records. Cells found in one run only are counted as
unmatched.
"""
import argparse
import collections
import glob
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from thesis_report.schema import RECORD_SCHEMA, InputError, load_records  # noqa: E402
from thesis_stats import fisher_exact, mcnemar_exact  # noqa: E402


def record_files(folder):
    """{experiment: records.jsonl path} of a run folder or a folder of runs."""
    own = os.path.join(folder, "records.jsonl")
    if os.path.isfile(own):
        return {os.path.basename(os.path.normpath(folder)): own}
    return {os.path.basename(os.path.dirname(p)): p for p in sorted(glob.glob(os.path.join(folder, "*", "records.jsonl")))}


def cells(folder, trials=None):
    """({cell: [k, n]}, {experiment: worker seconds}) of a folder's records;
    with a dict `trials`, also {(experiment, trial key): correct} into it."""
    counts = collections.defaultdict(lambda: [0, 0])
    seconds = collections.Counter()
    for exp, path in record_files(folder).items():
        for r in load_records(path, RECORD_SCHEMA):
            if trials is not None:
                trials[(exp, r["key"])] = bool(r.get("correct"))
            key = (exp, r["scene"], r.get("obj_id"), r["descriptor"], r["refinement"], r["added_noise_mm"],
                   json.dumps(r["params"], sort_keys=True))
            counts[key][0] += bool(r.get("correct"))
            counts[key][1] += 1
            seconds[exp] += r.get("wall_s", 0.0)
    return dict(counts), dict(seconds)


def compare(before, after):
    """The comparison as a dict (see the module doc)."""
    out = {"cells": 0, "equal": 0, "up": 0, "down": 0, "unmatched": 0, "correct_before": 0,
           "correct_after": 0, "trials": 0, "significant": [], "moved": []}
    for key in sorted(set(before) | set(after), key=str):
        if key not in before or key not in after:
            out["unmatched"] += 1
            continue
        (ka, na), (kb, nb) = before[key], after[key]
        out["cells"] += 1
        out["correct_before"] += ka
        out["correct_after"] += kb
        out["trials"] += na
        out["equal" if ka == kb else "up" if kb > ka else "down"] += 1
        cell = {"cell": list(key), "before": [ka, na], "after": [kb, nb], "p": fisher_exact(ka, na, kb, nb)}
        if ka != kb:
            out["moved"].append(cell)
        if cell["p"] < 0.05:
            out["significant"].append(cell)
    out["moved"].sort(key=lambda c: (-abs(c["after"][0] - c["before"][0]), str(c["cell"])))
    return out


def paired(before, after):
    """The trials of both runs ({(experiment, key): correct} each), paired:
    how many are in both, correct in the first only and in the second only,
    and McNemar's exact p of those two counts."""
    both = set(before) & set(after)
    first = sum(1 for t in both if before[t] and not after[t])
    second = sum(1 for t in both if after[t] and not before[t])
    return {"pairs": len(both), "before_only": first, "after_only": second, "p": mcnemar_exact(first, second)}


def name(cell):
    exp, scene, obj, desc, ref, noise, params = cell
    where = f"{exp} {scene}" + ("" if obj is None else f" obj {obj}")  # no obj_id: a failed trial's record
    return f"{where} {desc}+{ref} noise {noise:g}" + ("" if params == "{}" else f" {params}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--json", help="also write the comparison as JSON to this file")
    ap.add_argument("--moved", type=int, default=15, help="list this many of the cells that moved most")
    a = ap.parse_args(argv)
    runs, trials = [], ({}, {})
    for folder, t in zip((a.before, a.after), trials):
        try:
            c, s = cells(folder, t)
        except InputError as e:
            print(f"compare_runs.py: {e}", file=sys.stderr)
            return 2
        if not c:
            print(f"compare_runs.py: {folder}: no records.jsonl in it or in its subfolders", file=sys.stderr)
            return 2
        runs.append((c, s))
    r = compare(runs[0][0], runs[1][0])
    print(f"{r['cells']} cells, {r['trials']} trials: correct {r['correct_before']} -> {r['correct_after']}; "
          f"{r['equal']} equal, {r['up']} up, {r['down']} down, {len(r['significant'])} at p < 0.05 "
          f"(Fisher's exact test per cell); {r['unmatched']} in one run only")
    pr = paired(*trials)
    print(f"paired trials (experiment, trial key): {pr['pairs']}; correct before only {pr['before_only']}, "
          f"after only {pr['after_only']}; McNemar's exact test p = {pr['p']:.3g}")
    for c in r["significant"]:
        print(f"  p = {c['p']:.3g}: {name(c['cell'])} {c['before'][0]}/{c['before'][1]} -> {c['after'][0]}/{c['after'][1]}")
    for c in r["moved"][:a.moved]:
        print(f"  moved: {name(c['cell'])} {c['before'][0]}/{c['before'][1]} -> {c['after'][0]}/{c['after'][1]}")
    sb, sa = runs[0][1], runs[1][1]
    print("worker seconds (records' wall_s), before -> after:")
    for exp in sorted(set(sb) | set(sa)):
        print(f"  {exp}: {sb.get(exp, 0):.0f} -> {sa.get(exp, 0):.0f}")
    print(f"  total: {sum(sb.values()):.0f} -> {sum(sa.values()):.0f}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({**r, "paired": pr, "seconds_before": sb, "seconds_after": sa}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
