"""Number formats and the experiments' titles, shared by the README's sections."""


def pct(v):
    return "-" if v is None else "%.0f%%" % (100 * v)


def mean(v):
    v = [a for a in v if a is not None]
    return sum(v) / len(v) if v else None


def fmt_dur(s):
    s = int(round(s))
    return "%dh%02dm%02ds" % (s // 3600, s // 60 % 60, s % 60) if s >= 3600 else "%dm%02ds" % (s // 60, s % 60)


TITLES = {
    "table_4_1": "Table 4.1: LS5, several model views (12 synthetic, 8 real-sensor)",
    "table_4_3": "Table 4.3: LS5, one model view (from the side)",
    "table_4_4": "Table 4.4: LS5, one view, CRH skipped",
    "table_4_5": "Table 4.5: milk carton",
    "table_4_7": "Table 4.7: Statue of Liberty (armadillo stand-in)",
    "table_4_9": "Table 4.9: registration alone, statue, warehouse",
    "fig_4_6": "Figure 4.6: robustness and time vs number of hypotheses",
    "fig_4_7_global": "Figure 4.7 (global part): LS5 robustness vs added noise, CVFH CESF, 1 view",
    "fig_4_7_local": "Figure 4.7 (local part): LS5 robustness vs added noise, SHOT FPFH, 12 views",
    "fig_4_11_global": "Figure 4.11 (global part): statue robustness vs added noise, CVFH CESF, 1 view",
    "fig_4_11_local": "Figure 4.11 (local part): statue robustness vs added noise, SHOT FPFH, 12 views",
    "fig_4_12": "Figure 4.12: registration robustness vs added noise",
}


TABLES = ["table_4_1", "table_4_3", "table_4_4", "table_4_5", "table_4_7",
          "table_4_9"]


def short_title(e):
    return TITLES.get(e, e).split(":")[0]
