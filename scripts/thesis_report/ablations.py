"""The ablations: pairs of an experiment and its copy with one cause switched
back (configs/thesis/ablations.yaml), their cells compared, and which gaps to
the thesis they explain."""
import collections
import os

import thesis_ablations
from thesis_stats import fisher_exact, within_points

from .cells import POINTS, group_records, n_correct
from .formatting import mean, pct, short_title
from .schema import InputError


ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


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
    "it (same experiment, scene set and method) and switching the cause closes at least half the gap: the switched "
    "value lies within half the gap of the thesis's value, on either side, the two counts differing at p < 0.05 "
    "(Fisher's exact test). No correction is made for the %d %s tried, and an ablation that explains one cell can "
    "move others away (the table's last two columns): an explanation shows a set-up choice that can close the gap, "
    "not that the thesis made it.")


def ablation_row(a, compared, skipped):
    """A row of the ablations table: pairs run, cells compared and moved, means and cells near the thesis."""
    with_t = [m for m in compared if m.thesis is not None]

    def near(value):
        return "%d of %d" % (sum(within_points(value(m), m.thesis, POINTS) for m in with_t), len(with_t))
    return "| %s | %d of %d | %d | %d | %d | %s | %s | %s | %s |" % (
        a["name"], len(a["pairs"]) - len(skipped), len(a["pairs"]), len(compared), sum(m.moved for m in compared),
        sum(m.p < 0.05 for m in compared), pct(mean([m.a for m in compared])), pct(mean([m.b for m in compared])),
        near(lambda m: m.a) if with_t else "-", near(lambda m: m.b) if with_t else "-")


def ablations_table(res, ablations, cells):
    """(the table's lines, the line on pairs not run, [(ablation, its compared cells)])."""
    thesis = {(c.experiment, c.scenario, c.method): c.thesis for c in cells if c.measure == "robustness"
              and c.kind != "ablation"}
    rows = ["| ablation | pairs run | cells | moved > 15 points | p < 0.05 | mean, as reported | mean, switched back "
            "| within 15 of the thesis, as reported | switched back |", "|---|---|---|---|---|---|---|---|---|"]
    by_ablation, not_run = [], []
    for a in ablations:
        compared, skipped = ablation_cells(res, a, thesis)
        by_ablation.append((a, compared))
        if len(skipped) < len(a["pairs"]):
            rows.append(ablation_row(a, compared, skipped))
        if skipped:
            not_run.append("%s (%s)" % (a["name"], ", ".join(x for _e, _e2, missing in skipped for x in missing)))
    line = "Not run, no `results/thesis/raw/NAME/records.jsonl`: %s.\n" % "; ".join(not_run) if not_run else ""
    return rows, line, by_ablation


def gaps_text(cells, by_ablation):
    """Which main cells outside 15 points the ablations explain, and of the others which differ at p < 0.05."""
    gaps = [c for c in cells if c.main and not c.within]
    explained, unexplained = [], []
    for c in gaps:
        by = [a["name"] for a, compared in by_ablation for m in compared
              if (m.e, m.scenario, m.method, m.cond) == (c.experiment, c.scenario, c.method, "") and explains(m, c)]
        (explained if by else unexplained).append((c, by))
    o = ["Of the %d main cells outside 15 points, %d explained (%s), %d unexplained.\n" % (
        len(gaps), len(explained), "; ".join("%s %s %s by %s" % (short_title(c.experiment), c.scenario, c.method,
                                                                 ", ".join(by)) for c, by in explained) or "none",
        len(unexplained))]
    if unexplained:
        o.append("Unexplained (ours vs the thesis): " + "; ".join(
            "%s %s %s %s vs %s" % (short_title(c.experiment), c.scenario, c.method, pct(c.ours), pct(c.thesis))
            for c, _ in unexplained) + ".")
        chance = [c for c, _ in unexplained if c.p is not None and c.p >= 0.05]
        sig = len(unexplained) - len(chance)
        o[-1] += (" Of the %d unexplained, %d %s from the thesis's count at p < 0.05 (Fisher's exact test at the "
                 "thesis's n, as the scorecard) and %d %s not, so may be chance at these sample sizes: %s.\n" % (
                     len(unexplained), sig, "differs" if sig == 1 else "differ", len(chance),
                     "does" if len(chance) == 1 else "do",
                     "; ".join("%s %s %s %d/%d vs %s (p = %.2g)" % (short_title(c.experiment), c.scenario, c.method,
                                                                    c.k, c.n, pct(c.thesis), c.p)
                               for c in chance) or "none"))
    return o


def section_ablations(res, ablations, cells, path):
    o = ["## Ablations: what each change of the set-up does\n"]
    if not ablations:
        return o + ["No ablations (`%s` is missing or lists none).\n" % shown_path(path)]
    o.append("Command: `scripts/thesis.sh --ablations`. Each ablation runs experiments again with one cause switched "
             "back (`%s` says which and how). Per ablation: the cells compared, those that move by more than 15 "
             "points, those whose two counts differ at p < 0.05 (Fisher's exact test), the mean robustness and the "
             "cells within 15 points of the thesis, as reported and switched back. Each table cell: `cells.csv`, "
             "kind `ablation`.\n" % shown_path(path))
    rows, not_run, by_ablation = ablations_table(res, ablations, cells)
    o += rows + [""] + ([not_run] if not_run else [])
    gaps = [c for c in cells if c.main and not c.within]
    o.append("**Which gaps to the thesis the ablations explain.** " + EXPLAIN_RULE % (
        len(gaps), len(ablations), "ablation" if len(ablations) == 1 else "ablations") + "\n")
    return o + gaps_text(cells, by_ablation)
