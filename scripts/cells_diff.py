#!/usr/bin/env python3
"""Robustness cells of two thesis regenerations side by side.

    python3 scripts/cells_diff.py BEFORE.csv AFTER.csv [--scenes PREFIX[,PREFIX...]]

Reads two results/thesis/cells.csv files (e.g. `git show REV:results/thesis/cells.csv`
for the one before a change), keeps the main experiments' robustness cells
whose scene set starts with one of the prefixes (default: the real-sensor sets,
table_astra and table_kinect_one), and prints a Markdown table: each cell's
k/n before and after, the thesis's value, and whether the change moved it
toward the thesis (closer by more than half a point), away, or not.
"""
import argparse
import csv
import sys


def robustness_cells(path, prefixes):
    """(table, scenario, method) -> row, for the main robustness cells of the given scene sets."""
    out = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["kind"] != "main" or row["measure"] != "robustness" or not row["ours_k"]:
                continue
            if not any(row["scenario"].startswith(p) for p in prefixes):
                continue
            out[(row["table"], row["scenario"], row["method"])] = row
    return out


def direction(before, after, thesis):
    """'toward', 'away' or 'same': the change of |ours - thesis| beyond half a point."""
    d0, d1 = abs(before - thesis), abs(after - thesis)
    if d1 < d0 - 0.005:
        return "toward"
    if d1 > d0 + 0.005:
        return "away"
    return "same"


def table(before, after):
    lines = ["| table | scene set | method | before | after | thesis | moved |", "|---|---|---|---|---|---|---|"]
    counts = {"toward": 0, "away": 0, "same": 0}
    for key in sorted(set(before) & set(after)):
        b, a = before[key], after[key]
        thesis = float(a["thesis"])
        move = direction(float(b["ours"]), float(a["ours"]), thesis)
        counts[move] += 1
        lines.append(f"| {key[0]} | {key[1]} | {key[2]} | {b['ours_k']}/{b['n']} | {a['ours_k']}/{a['n']} | "
                     f"{100 * thesis:.0f}% | {move} |")
    lines.append("")
    lines.append(f"{counts['toward']} toward the thesis, {counts['away']} away, {counts['same']} unchanged.")
    return "\n".join(lines), counts


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--scenes", default="table_astra,table_kinect_one")
    a = ap.parse_args(argv)
    prefixes = [p for p in a.scenes.split(",") if p]
    text, _ = table(robustness_cells(a.before, prefixes), robustness_cells(a.after, prefixes))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
