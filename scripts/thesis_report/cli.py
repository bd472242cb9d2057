"""Writes results/thesis/README.md and cells.csv from the raw results of scripts/thesis.sh.

    scripts/thesis_report.py OUT EXPERIMENT... [--ablations FILE] [--scorecard-json FILE]

--scorecard-json FILE: write only the agreement scorecard and the verdicts as
JSON to FILE ("-": stdout), no README. --ablations FILE: the ablation pairs
(default configs/thesis/ablations.yaml; a missing file means none).

OUT is results/thesis: each experiment's folder OUT/raw/NAME holds what
`posebench run` and `posebench report` wrote (experiment.json, records.jsonl,
runs.jsonl, report.md, report.csv, plots.json); merged plots go to OUT/plots.
Every record is checked against the trial record's schema (`posebench schema
record` of the binary in POSEBENCH, default build/posebench, or its copy
thesis_report/record_schema.json without a binary): an unknown key or
a missing required key is an error naming the file, the line and the key
(exit code 2).
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
import json
import os
import sys

from .ablations import ABLATIONS, load_ablations
from .cells import all_cells, write_cells_csv
from .conclusions import verdicts
from .readme import host_info, readme
from .results import load_results
from .schema import RECORD_SCHEMA, InputError, schema_from_binary
from .scorecard import scorecard


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
              "thesis_report/record_schema.json" % binary, file=sys.stderr)
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
