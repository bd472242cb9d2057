"""The agreement scorecard: per main table, in total and per variant, how many
cells are within 15 points of the thesis, differ from it at p < 0.05 and
p < 0.01, and how many rows agree on the best method and on the order."""
import collections
import json
import os

from thesis_stats import fitting_n, kendall_tau

from .cells import FACES, MAIN_CELLS, MAIN_TABLES, THESIS_N_TEXT
from .formatting import mean, pct


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
    "The earlier set-up's row is this scorecard of a run with 10 images per cell, training views at 0 and 20 degrees, "
    "a floor and a wall in the warehouse, the Astra before its calibration, occluded targets 40-90%% visible and CESF "
    "without its fallback (`%s` beside this README).")


def scorecard_before(res):
    """The totals of OUT/scorecard_before.json (a run of the earlier set-up, BEFORE_TEXT), or None."""
    path = os.path.join(os.path.dirname(res.raw.rstrip(os.sep)), SCORECARD_BEFORE)
    try:
        with open(path) as f:
            total = json.load(f)["total"]
        return total if all(k in total for k in ("cells", "within_15", "significant_05", "significant_01", "rows",
                                                  "best_agrees", "tau_positive", "mean_ours", "mean_thesis")) else None
    except (OSError, ValueError, KeyError, TypeError):
        return None


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


def scorecard_line(name, s):
    return "| %s | %d | %d | %d | %d | %d | %d | %d | %s | %s |" % (
        name, s["cells"], s["within_15"], s["significant_05"], s["significant_01"], s["rows"], s["best_agrees"],
        s["tau_positive"], pct(s["mean_ours"]), pct(s["mean_thesis"]))


def section_agreement(res, cells, card):
    if not card["tables"] and not card["variants"]:
        return []
    o = ["## Agreement with the thesis\n",
         "Command: `scripts/thesis.sh --readme-only`; as JSON: the `--scorecard-json` line above. Robustness cells of "
         "the thesis's Tables 4.1-4.9 (%d values; the milk carton judged with the model's symmetries). Within 15: "
         "|ours - thesis| <= 15 points. p: Fisher's exact test (two-sided), our k/n against the thesis's round(value "
         "x n)/n. Best agrees: a method is the most robust (ties included) both here and in the thesis's row. "
         "tau > 0: Kendall's tau-b of the row against the thesis's is positive (a row all tied does not count).\n" %
         MAIN_CELLS,
         "| table | cells | within 15 points | p < 0.05 | p < 0.01 | rows | best agrees | tau > 0 | mean, ours | "
         "mean, thesis |", "|---|---|---|---|---|---|---|---|---|---|"]
    o += [scorecard_line("Table " + t["table"], t) for t in card["tables"]]
    t = card["total"]
    if t["cells"]:
        o.append(scorecard_line("**total** (of the thesis's %d)" % t["of"], t))
    before = scorecard_before(res) if t["cells"] else None
    if before:
        o.append(scorecard_line("total, earlier set-up (`%s`)" % SCORECARD_BEFORE, before))
    o += [scorecard_line("not counted: Table %s %s%s" % (v["table"], v["experiment"], ", faces on faces (the "
                                                           "thesis's judgement)" if v["measure"] == FACES else ""), v)
          for v in card["variants"]]
    o += ["", " ".join(t for t in (inexact_text(cells), direction_text(cells)) if t), ""]
    if before:
        o += [BEFORE_TEXT % SCORECARD_BEFORE, ""]
    return o
