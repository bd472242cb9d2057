"""The README's tables: the rows of each table experiment's report.md that
the thesis printed, the robustness cells rewritten from the counted cells,
and the milk carton's and Table 4.9's extra lines."""
import collections
import statistics

from .cells import FACES, THESIS_N_TEXT, carton_counts, thesis_protocol
from .formatting import TABLES, TITLES, mean, pct


def fmt_rob(c):
    """`70% 7/10 [39-89] (35%) *`: ours, k/n, 95% Wilson interval, the thesis's value, Fisher's mark."""
    return "%s %d/%d [%.0f-%.0f] (%s)%s" % (pct(c.ours), c.k, c.n, 100 * c.lo, 100 * c.hi, pct(c.thesis), c.mark())


def legend(cells):
    return ("Robustness cells read `70%% 7/10 [39-89] (35%%) *`: our fraction correct, the count k/n from the "
            "records, its 95%% Wilson interval (%%), the thesis's value in parentheses, and a mark when Fisher's exact "
            "test (two-sided) of our k/n against the thesis's k/n is significant: `*` p < 0.05, `**` p < 0.01. The "
            "thesis's n per cell: %s; its k = round(value x n). %s\n" % (THESIS_N_TEXT, sample_sizes_text(cells)))


def sample_sizes_text(cells):
    """Our trials per cell, per experiment shown (from the records; the ablations' are in cells.csv)."""
    per = collections.OrderedDict()
    for c in cells:
        if c.counted and c.measure == "robustness" and c.kind != "ablation":
            per.setdefault(c.experiment, set()).add(c.n)
    return "Our n per cell (trials, from the records): " + "; ".join(
        "%s %s" % (e, "-".join(str(v) for v in sorted({min(ns), max(ns)}))) for e, ns in per.items()) + "."


FACES_LABEL = "faces on faces (the thesis's judgement)"


def md_row(cells):
    return "| " + " | ".join(cells) + " |"


def has_faces(e, cells):
    """Whether a table shows the faces-on-faces row: the milk carton's, or any with such cells."""
    return e == "table_4_5" or any(c.experiment == e and c.measure == FACES for c in cells)


def table_rows(res, e, cells=()):
    """The first table of report.md, with the rows the thesis printed a value in: each robustness
    row rewritten from `cells` (count, interval, the thesis's value, mark) and, for the milk carton,
    a faces-on-faces row after it ("-" without judged records); then the rows with a thesis value in
    parentheses (time; Table 4.9's errors). The other rows (ours only) stay in report.md."""
    lookup = {(c.scenario, c.measure, c.method): c for c in cells if c.experiment == e and c.counted}
    faces = has_faces(e, cells)
    out, methods, scene = [], None, ""
    for line in res[e].md.splitlines():
        parts = line.split("|")
        if methods is None:
            if line.startswith("| scenario | measure |"):
                methods = [p.strip() for p in parts[3:-1]]
                out.append(line)
            continue
        if not line.startswith("|"):
            break
        if line.startswith("|---") or len(parts) < len(methods) + 4:
            out.append(line)
            continue
        values = [p.strip() for p in parts[-1 - len(methods):-1]]
        label = "|".join(parts[2:-1 - len(methods)]).strip()  # "rotation error (1-|p.q|)" holds a "|"
        scene = parts[1].strip() or scene
        if label == "robustness":
            new = [lookup.get((scene, "robustness", m)) for m in methods]
            out.append(md_row([parts[1].strip(), label] + [fmt_rob(c) if c else v for c, v in zip(new, values)]))
            if faces:
                new = [lookup.get((scene, FACES, m)) for m in methods]
                out.append(md_row(["", FACES_LABEL] + [fmt_rob(c) if c else "-" for c in new]))
        elif label != "robustness, judged by faces" and any("(" in v for v in values):
            out.append(line)
    return out


def carton_note(res, e):
    """What the milk carton's two judgements are, and a note when its records predate the faces one."""
    o = ["The carton is judged with its model's symmetries (the half turn about its vertical axis, "
         "`models/models.yaml`); the faces-on-faces row judges it as the thesis did, correct \"when its faces lie on "
         "the true object's faces, even upside down\" (any of the 8 rotations of the 70 x 70 x 195 mm body).\n"]
    if not carton_counts(res[e].records)[1]:
        o.append("These records carry no `judgements.faces` (made before that judgement existed): re-run table_4_5 "
                 "(remove `results/thesis/raw/table_4_5`, then `scripts/thesis.sh --only table_4_5`).\n")
    return o


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
    return ["Accuracy as the thesis defines it (section 4.1.2: the standard deviation of the errors over the correct "
            "trials; the mean and the largest beside it). Over the %d images where at least one method is correct, "
            "as the thesis counted: %s. Why ICP point-to-plane is the most accurate here and the least in the thesis: "
            "`results/thesis/FINDINGS.md`, Table 4.9 (reciprocal correspondences)." % (
                len(images), "; ".join(parts))]


def registration_times(res, e):
    meth = res[e].exp["refinements"]
    rt = {m: mean([r.get("times", {}).get("refine") for r in res[e].records if r["refinement"] == m]) for m in meth}
    return ["The time row is the whole call; the registration alone took on average: " +
            ", ".join("%s %.3f s" % (m, rt[m]) for m in meth if rt[m] is not None) + " (the thesis: 0.02 to 0.09 s).\n"]


def table_section(res, e, cells):
    o = ["### %s" % TITLES[e],
         "Command: `scripts/thesis.sh --only %s`; config: `configs/thesis/%s.yaml`.\n" % (e, e),
         "\n".join(table_rows(res, e, cells)) + "\n"]
    if has_faces(e, cells):
        o += carton_note(res, e)
    if e == "table_4_9":
        o.append(registration_accuracy(res, e)[0] + " " + registration_times(res, e)[0])
    return o


def section_tables(res, cells):
    o = ["## Tables\n",
         "Rows: scene set and measure, the rows the thesis printed (the others are in each experiment's `report.md`); "
         "columns: descriptor (refinement in Table 4.9). Robustness: the fraction of images whose chosen pose is "
         "correct (translation error < 50 mm on tables, < 100 mm in the warehouse, 1 - |p.q| < 0.05, "
         "symmetry-aware); time: mean online seconds per image; errors: means over the correct trials. "
         "`table_astra` and `table_kinect_one` use the simulated sensors. " + legend(cells)]
    for e in TABLES:
        if e in res:
            o += table_section(res, e, cells)
    return o
