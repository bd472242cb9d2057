"""The thesis's conclusions: our numbers and the thesis's own as
scripts/thesis_verdicts.py's rules read them, and the README's section."""
import collections
import os

from thesis_verdicts import Curve, Data, evaluate

from .cells import experiment_json, method_column, n_correct, table_of
from .formatting import mean
from .schema import InputError


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


def cell_text(text):
    """Text as one markdown table cell."""
    return text.replace("|", "\\|")


def section_conclusions(res, cells):
    found = [v for v in verdicts(res, cells) if v[3] is not None]
    if not found:
        return []
    o = ["## The thesis's conclusions against these numbers\n",
         "Command: `scripts/thesis.sh --readme-only`; as JSON: the `--scorecard-json` line above. Each verdict applies "
         "a rule of `scripts/thesis_verdicts.py`, fixed before the run, to the records; the same rule applied to the "
         "thesis's own table values (k = round(value x n)) checks the rule.\n",
         "| | conclusion | here | on the thesis's numbers | evidence here |", "|---|---|---|---|---|"]
    for cid, title, _rule, v, theirs in found:
        o.append("| %s | %s | **%s** | %s | %s |" % (cid, cell_text(title), v.word,
                                                      theirs.word if theirs else "no numbers (figures only)",
                                                      cell_text(v.evidence)))
    return o + [""]
