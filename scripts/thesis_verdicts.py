"""The thesis's seven conclusions, each judged by a rule fixed before the run.

One pure function per conclusion takes a Data (counts of correct trials per
cell, mean times, accuracies, curves; no files) and returns a Verdict: the
verdict word, the evidence text with the counts it used, and those counts as
numbers. RULES[cid] is the rule as the README prints it, verbatim, before the
evidence. The same functions run on the thesis's own numbers (thesis_data()
in scripts/thesis_report/conclusions.py) as a check of the rules.

Verdict words: "supported", "partly supported", "not supported"; each rule
says when which. A function returns None when the experiments it needs are
missing.
"""
import collections

from thesis_stats import fisher_exact

SUPPORTED, PARTLY, NOT = "supported", "partly supported", "not supported"
GLOBAL = ("cvfh", "cesf")          # the thesis's working global descriptors (ESF it found poor)
GLOBAL3 = ("cvfh", "esf", "cesf")
LOCAL = ("shot", "fpfh")
FPS30 = 1 / 30
ALPHA = 0.05

# A noise curve of a figure experiment: points {x: (correct, trials, mean time or None)}.
Curve = collections.namedtuple("Curve", "figure scene method points")
Verdict = collections.namedtuple("Verdict", "word evidence numbers")


class Data:
    """What the rules read.

    rob: {(experiment, scene, method): (correct, trials)}, in table order;
    time: {(experiment, scene, method): mean seconds per image};
    accuracy: {(experiment, scene, method): (translation_mm, rotation_1mpq)};
    curves: [Curve] of the figure experiments (noise sweeps, Figure 4.6);
    registration_only: experiments that refine the ground truth (no recognition)."""

    def __init__(self, rob=None, time=None, accuracy=None, curves=(), registration_only=()):
        self.rob, self.time, self.accuracy = dict(rob or {}), dict(time or {}), dict(accuracy or {})
        self.curves, self.registration_only = list(curves), set(registration_only)

    def frac(self, e, s, m):
        kn = self.rob.get((e, s, m))
        return None if kn is None or not kn[1] else kn[0] / kn[1]

    def scenes(self, e):
        out = []
        for (x, s, _m) in self.rob:
            if x == e and s not in out:
                out.append(s)
        return out


def word(checks):
    """supported when every check holds, not supported when none, else partly."""
    checks = list(checks)
    return SUPPORTED if all(checks) else (PARTLY if any(checks) else NOT)


def pct(v):
    return "-" if v is None else "%.0f%%" % (100 * v)


def best(d, e, s, methods):
    """(fraction, (k, n)) of the most robust of `methods` in a row, or None."""
    have = [(d.frac(e, s, m), d.rob[(e, s, m)]) for m in methods if d.frac(e, s, m) is not None]
    return max(have, key=lambda h: h[0]) if have else None


def mean(v):
    v = [a for a in v if a is not None]
    return sum(v) / len(v) if v else None


def held(part):
    return "not run" if part is None else ("holds" if part else "fails")


def majority(x, of):
    return of > 0 and x > of / 2


# ---- 1 -----------------------------------------------------------------------------

TIME_TABLES = ("table_4_1", "table_4_3", "table_4_5", "table_4_7")
SMOOTH_TABLES = (("table_4_1", "LS5"), ("table_4_3", "LS5"), ("table_4_5", "milk carton"))
CLUTTER_TABLES = ("table_4_1", "table_4_3", "table_4_7")

RULE_1 = (
    "Three parts, each over every row it concerns. (a) Fast: in the rows of Tables 4.1, 4.3, 4.5 and 4.7, the mean "
    "time per image of CVFH and CESF (the thesis's global descriptors; it found ESF poor) is below that of SHOT and "
    "FPFH in more than half of the rows. (b) Robust on smooth objects: in the table-scene rows of the LS5 (Tables "
    "4.1, 4.3) and the milk carton (Table 4.5), the better of CVFH/CESF is at least as robust as the better of "
    "SHOT/FPFH in more than half of the rows. (c) Local better for large objects in clutter: in the warehouse rows "
    "(Tables 4.1, 4.3 and 4.7), the better of SHOT/FPFH is more robust than the better of CVFH/CESF in more than "
    "half of the rows. Supported: all three parts hold; partly supported: one or two; not supported: none (a part "
    "whose experiments were not run is left out).")


def conclusion_1(d):
    rows_t = [(e, s) for e in TIME_TABLES for s in d.scenes(e)]
    t = [(mean([d.time.get((e, s, m)) for m in GLOBAL]), mean([d.time.get((e, s, m)) for m in LOCAL]))
         for e, s in rows_t]
    t = [p for p in t if None not in p]
    faster = sum(1 for g, lo in t if g < lo)
    smooth = collections.OrderedDict()
    for e, obj in SMOOTH_TABLES:
        for s in d.scenes(e):
            if s.startswith("table"):
                g, lo = best(d, e, s, GLOBAL), best(d, e, s, LOCAL)
                if g and lo:
                    smooth.setdefault(obj, []).append(g[0] >= lo[0])
    sm_yes = sum(sum(v) for v in smooth.values())
    sm_all = sum(len(v) for v in smooth.values())
    clutter = []
    for e in CLUTTER_TABLES:
        for s in d.scenes(e):
            if s.startswith("warehouse"):
                g, lo = best(d, e, s, GLOBAL), best(d, e, s, LOCAL)
                if g and lo:
                    clutter.append(lo[0] > g[0])
    if not t and not sm_all and not clutter:
        return None
    # a part without rows (its experiments not run) is left out of the verdict
    parts = [majority(yes, of) if of else None for yes, of in
             ((faster, len(t)), (sm_yes, sm_all), (sum(clutter), len(clutter)))]
    ev = ("(a) global faster in %d of %d rows: %s. (b) the better global at least as robust in %d of %d smooth-object "
          "table rows (%s): %s. (c) the better local more robust in %d of %d warehouse rows: %s." % (
              faster, len(t), held(parts[0]), sm_yes, sm_all,
              ", ".join("%s %d of %d" % (o, sum(v), len(v)) for o, v in smooth.items()) or "none run",
              held(parts[1]), sum(clutter), len(clutter), held(parts[2])))
    return Verdict(word(p for p in parts if p is not None), ev, {
        "time_rows": len(t), "global_faster": faster, "smooth_rows": sm_all, "global_at_least_as_robust": sm_yes,
        "warehouse_rows": len(clutter), "local_more_robust": sum(clutter),
        "parts_holding": sum(1 for p in parts if p)})


# ---- 2 -----------------------------------------------------------------------------

CESF_TABLES = ("table_4_1", "table_4_3", "table_4_4", "table_4_5", "table_4_7")
ESF_POOR = 0.20

RULE_2 = (
    "Over every row of Tables 4.1, 4.3, 4.4, 4.5 and 4.7 (the milk carton judged with the model's symmetries): (a) "
    "CESF is at least as robust as both CVFH and ESF in more than half of the rows (a row where CESF is below either "
    "counts as behind; whether that shortfall is significant, Fisher p < 0.05 against the better of the two, is "
    "reported, not used); (b) ESF is poor: at most 20% correct in more than half of the rows (every table used 1 to "
    "15 model views, against the 80 of ESF's authors). Supported: both hold; partly supported: one; not supported: "
    "neither.")


def conclusion_2(d):
    rows = [(e, s) for e in CESF_TABLES for s in d.scenes(e)
            if all(d.frac(e, s, m) is not None for m in GLOBAL3)]
    if not rows:
        return None
    ahead = tied = behind = behind_sig = esf_poor = 0
    for e, s in rows:
        c = d.frac(e, s, "cesf")
        other = best(d, e, s, ("cvfh", "esf"))
        if c > other[0] + 1e-12:
            ahead += 1
        elif c >= other[0] - 1e-12:
            tied += 1
        else:
            behind += 1
            kc, nc = d.rob[(e, s, "cesf")]
            if fisher_exact(kc, nc, other[1][0], other[1][1]) < ALPHA:
                behind_sig += 1
        esf_poor += d.frac(e, s, "esf") <= ESF_POOR + 1e-12
    n = len(rows)
    parts = (majority(ahead + tied, n), majority(esf_poor, n))
    means = [mean([d.frac(e, s, m) for e, s in rows]) for m in GLOBAL3]
    ev = ("(a) CESF ahead of both in %d, tied best in %d, behind in %d of %d rows (behind at p < 0.05 in %d): %s. (b) "
          "ESF at most 20%% in %d of %d rows: %s. Mean robustness over these rows: CVFH %s, ESF %s, CESF %s." % (
              ahead, tied, behind, n, behind_sig, "holds" if parts[0] else "fails", esf_poor, n,
              "holds" if parts[1] else "fails", pct(means[0]), pct(means[1]), pct(means[2])))
    return Verdict(word(parts), ev, {"rows": n, "cesf_ahead": ahead, "cesf_tied": tied, "cesf_behind": behind,
                                     "cesf_behind_significant": behind_sig, "esf_poor_rows": esf_poor})


# ---- 3 -----------------------------------------------------------------------------

CRH_PAIRS = (("table_4_4", "table_4_3", "one model view"),)

RULE_3 = (
    "Table 4.4 (CRH skipped) against Table 4.3 (with CRH), over the CVFH and CESF cells of the same scene sets: "
    "skipping the CRH helps when the mean robustness without CRH is higher than with it and more cells rise than "
    "fall. Supported: it helps; not supported: it does not. Cells whose change is significant (Fisher p < 0.05) are "
    "counted for the reader.")


def conclusion_3(d):
    out, checks, numbers = [], [], {}
    for skip, crh, what in CRH_PAIRS:
        cells = [(s, m) for s in d.scenes(skip) for m in GLOBAL
                 if d.frac(skip, s, m) is not None and d.frac(crh, s, m) is not None]
        if not cells:
            continue
        up = sum(1 for s, m in cells if d.frac(skip, s, m) > d.frac(crh, s, m))
        down = sum(1 for s, m in cells if d.frac(skip, s, m) < d.frac(crh, s, m))
        sig_up = sum(1 for s, m in cells if d.frac(skip, s, m) > d.frac(crh, s, m)
                     and fisher_exact(*(d.rob[(skip, s, m)] + d.rob[(crh, s, m)])) < ALPHA)
        sig_down = sum(1 for s, m in cells if d.frac(skip, s, m) < d.frac(crh, s, m)
                       and fisher_exact(*(d.rob[(skip, s, m)] + d.rob[(crh, s, m)])) < ALPHA)
        m_with, m_without = mean([d.frac(crh, s, m) for s, m in cells]), mean([d.frac(skip, s, m) for s, m in cells])
        helps = m_without > m_with and up > down
        checks.append(helps)
        numbers[skip] = {"cells": len(cells), "up": up, "down": down, "up_significant": sig_up,
                         "down_significant": sig_down, "mean_with_crh": m_with, "mean_without_crh": m_without}
        out.append("with %s, %s -> %s on average over %d cells, %d rise (%d at p < 0.05), %d fall (%d at p < 0.05): "
                   "%s" % (what, pct(m_with), pct(m_without), len(cells), up, sig_up, down, sig_down,
                           "helps" if helps else "does not help"))
    if not checks:
        return None
    return Verdict(word(checks), "Robustness with CRH -> without: " + "; ".join(out) + ".", numbers)


# ---- 4 -----------------------------------------------------------------------------

REGISTRATION_TABLE, REGISTRATION_FIGURE = "table_4_9", "fig_4_12"

RULE_4 = (
    "(a) ICP (point to point) has the lowest mean rotation error (1 - |p.q|) over the correct trials of Table 4.9 "
    "(ties count as lowest). Rotation, because it is the only reading the thesis's own Table 4.9 bears out: there "
    "ICP has the lowest rotation error (0.0004) but the third-lowest translation error (8.46 mm; ICP-LM 5.69 mm). "
    "(b) ICP point-to-plane is among the most robust (ties included) in Table 4.9 and, when Figure 4.12 ran, over "
    "all its noise levels pooled. Supported: both; partly supported: (a) only; not supported: (a) fails, whatever "
    "(b) gives. The mean translation errors are reported beside it.")


def pooled(curve_list, method):
    k = sum(p[0] for c in curve_list if c.method == method for p in c.points.values())
    n = sum(p[1] for c in curve_list if c.method == method for p in c.points.values())
    return (k, n) if n else None


def conclusion_4(d):
    e = REGISTRATION_TABLE
    keys = [(s, m) for (x, s, m) in d.rob if x == e]
    if not keys:
        return None
    s0 = keys[0][0]
    meth = [m for s, m in keys if s == s0]
    te = {m: d.accuracy.get((e, s0, m), (None, None))[0] for m in meth}
    re = {m: d.accuracy.get((e, s0, m), (None, None))[1] for m in meth}
    acc = [m for m in meth if re[m] is not None]
    if "icp" not in acc:
        return None
    lowest = min(re[m] for m in acc)
    a = re["icp"] <= lowest * (1 + 1e-9) + 1e-15
    top = max(d.frac(e, s0, m) for m in meth)
    most_robust = [m for m in meth if d.frac(e, s0, m) >= top - 1e-12]
    curves = [c for c in d.curves if c.figure == REGISTRATION_FIGURE]
    fig = {m: pooled(curves, m) for m in meth if pooled(curves, m)}
    fig_top = max(k / n for k, n in fig.values()) if fig else None
    fig_most = [m for m, (k, n) in fig.items() if k / n >= fig_top - 1e-12]
    b = "icp_plane" in most_robust and (not fig or "icp_plane" in fig_most)
    v = NOT if not a else (SUPPORTED if b else PARTLY)
    lowest_of = [m for m in acc if re[m] <= lowest * (1 + 1e-9) + 1e-15]
    ev = ("(a) mean rotation error in Table 4.9: %s; lowest: %s: %s (translation: %s). (b) most robust in Table 4.9: "
          "%s (%s)%s: %s." % (
        ", ".join("%s %.2g" % (m, re[m]) for m in acc), ", ".join(lowest_of), "holds" if a else "fails",
        ", ".join("%s %.2f mm" % (m, te[m]) for m in acc if te[m] is not None),
        ", ".join(most_robust), pct(top),
        ("; over Figure 4.12's noise levels pooled: " + ", ".join("%s %d/%d" % (m, k, n) for m, (k, n) in fig.items())
         + ", most robust " + ", ".join(fig_most)) if fig else "", "holds" if b else "fails"))
    return Verdict(v, ev, {"icp_lowest_rotation": a, "lowest": lowest_of,
                           "icp_plane_most_robust": b, "most_robust_table": most_robust,
                           "most_robust_figure": fig_most})


# ---- 5 -----------------------------------------------------------------------------

RULE_5 = (
    "Every mean time per image of a recognition cell (every table and figure experiment except the registration-only "
    "Table 4.9 and Figure 4.12; figures per point) is above 1/30 s. Supported: all are; not supported: some cell ran "
    "at 30 frames per second or faster.")


def time_cells(d):
    """(seconds, where) of every recognition time cell: tables, then figure points."""
    out = [(t, "%s %s %s" % k) for k, t in d.time.items() if k[0] not in d.registration_only and t is not None]
    out += [(p[2], "%s %s %s at %g" % (c.figure, c.scene, c.method, x)) for c in d.curves
            if c.figure not in d.registration_only for x, p in c.points.items() if p[2] is not None]
    return out


def conclusion_5(d):
    cells = time_cells(d)
    if not cells:
        return None
    fast = [c for c in cells if c[0] <= FPS30]
    lo, hi = min(cells), max(cells)
    ev = ("%d time cells from %.3f s (%s) to %.2f s (%s); %d at or below 1/30 s%s." % (
        len(cells), lo[0], lo[1], hi[0], hi[1], len(fast),
        (": " + "; ".join("%s %.3f s" % (w, t) for t, w in sorted(fast)[:8]) +
         ("; and %d more" % (len(fast) - 8) if len(fast) > 8 else ""))
        if fast else ""))
    return Verdict(NOT if fast else SUPPORTED, ev, {"cells": len(cells), "at_30fps": len(fast), "fastest_s": lo[0],
                                                   "slowest_s": hi[0]})


# ---- 6 -----------------------------------------------------------------------------

NOISE_FIGURES = ("fig_4_7_global", "fig_4_7_local", "fig_4_11_global", "fig_4_11_local", "fig_4_12")

RULE_6 = (
    "Over every curve of Figures 4.7, 4.11 and 4.12 with points at 0 and 2 mm: a curve is up when its robustness at "
    "2 mm is higher than at 0 mm and the two counts differ at p < 0.05 (Fisher's exact test), down when lower with "
    "p < 0.05, flat otherwise (a change within sampling noise is not counted). Supported: more curves up than down "
    "and up in more than half of the curves; partly supported: more up than down, but not in more than half; not "
    "supported: otherwise. The changes in direction alone, significant or not, are reported.")


def conclusion_6(d):
    cmp_ = [(c, c.points[0.0], c.points[2.0]) for c in d.curves if c.figure in NOISE_FIGURES
            and 0.0 in c.points and 2.0 in c.points and c.points[0.0][1] and c.points[2.0][1]]
    if not cmp_:
        return None
    up, down, raw_up, raw_down = [], [], 0, 0
    for c, p0, p2 in cmp_:
        f0, f2 = p0[0] / p0[1], p2[0] / p2[1]
        raw_up += f2 > f0
        raw_down += f2 < f0
        if f2 != f0 and fisher_exact(p0[0], p0[1], p2[0], p2[1]) < ALPHA:
            (up if f2 > f0 else down).append((c, p0, p2))
    n = len(cmp_)
    v = SUPPORTED if len(up) > len(down) and majority(len(up), n) else (PARTLY if len(up) > len(down) else NOT)
    flat = n - len(up) - len(down)

    def desc(lst):
        return "; ".join("%s %s %s %d/%d -> %d/%d" % (c.figure, c.scene, c.method, p0[0], p0[1], p2[0], p2[1])
                         for c, p0, p2 in lst) or "none"
    ev = ("%d curves: %d up, %d down, %d flat at p < 0.05 (up: %s; down: %s). In direction alone: %d higher at 2 mm, "
          "%d lower, %d equal." % (n, len(up), len(down), flat, desc(up), desc(down), raw_up, raw_down,
                                   n - raw_up - raw_down))
    return Verdict(v, ev, {"curves": n, "up": len(up), "down": len(down), "flat": flat, "higher": raw_up,
                           "lower": raw_down})


# ---- 7 -----------------------------------------------------------------------------

NOISE_PAIRS = (("fig_4_7", "LS5"), ("fig_4_11", "statue"))

RULE_7 = (
    "Per figure (4.7, 4.11) and scene set: all correct trials of CVFH and CESF over all noise levels pooled, against "
    "those of SHOT and FPFH; the global ones are more robust against noise there when their pooled fraction is "
    "higher. Supported: in every figure and scene set run; partly supported: in some; not supported: in none. The "
    "Fisher p of each pooled comparison is reported.")


def conclusion_7(d):
    rows, checks = [], []
    for fig, obj in NOISE_PAIRS:
        scenes = []
        for c in d.curves:
            if c.figure in (fig + "_global", fig + "_local") and c.scene not in scenes:
                scenes.append(c.scene)
        for s in scenes:
            kn = []
            for part, meths in (("_global", GLOBAL), ("_local", LOCAL)):
                cs = [c for c in d.curves if c.figure == fig + part and c.scene == s and c.method in meths]
                k = sum(p[0] for c in cs for p in c.points.values())
                n = sum(p[1] for c in cs for p in c.points.values())
                kn.append((k, n))
            if not kn[0][1] or not kn[1][1]:
                continue
            g, lo = kn[0][0] / kn[0][1], kn[1][0] / kn[1][1]
            checks.append(g > lo)
            rows.append("Figure %s (%s) %s: global %d/%d (%s) vs local %d/%d (%s), p = %.2g" % (
                fig[4:].replace("_", "."), obj, s, kn[0][0], kn[0][1], pct(g), kn[1][0], kn[1][1], pct(lo),
                fisher_exact(kn[0][0], kn[0][1], kn[1][0], kn[1][1])))
    if not checks:
        return None
    return Verdict(word(checks), "Global higher in %d of %d: %s." % (sum(checks), len(checks), "; ".join(rows)),
                   {"rows": len(checks), "global_higher": sum(checks)})


# ---- all ---------------------------------------------------------------------------

CONCLUSIONS = [
    ("C1", "Global descriptors are fast and robust for objects with a smooth visible surface; local descriptors win "
           "for larger objects in clutter and occlusion", RULE_1, conclusion_1),
    ("C2", "CESF is more robust than the other global descriptors; ESF is poor with few model views", RULE_2,
     conclusion_2),
    ("C3", "CRH is the weak link of the global pipeline (Table 4.4 vs 4.3)", RULE_3, conclusion_3),
    ("C4", "ICP is the most accurate registration, ICP point-to-plane the most robust", RULE_4, conclusion_4),
    ("C5", "Nothing ran at 30 frames per second", RULE_5, conclusion_5),
    ("C6", "Better with about 2 mm of added noise than with none (thesis section 5.1)", RULE_6, conclusion_6),
    ("C7", "The global descriptors are more robust against noise than the local ones (thesis section 5.1, "
           "Figure 4.7)", RULE_7, conclusion_7),
]
RULES = {cid: rule for cid, _t, rule, _f in CONCLUSIONS}


def evaluate(d):
    """[(id, title, rule, Verdict or None)] of the seven conclusions on d."""
    return [(cid, title, rule, f(d)) for cid, title, rule, f in CONCLUSIONS]
