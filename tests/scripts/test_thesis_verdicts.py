"""scripts/thesis_stats.py and scripts/thesis_verdicts.py: known values of the
statistics, and each conclusion's rule on small in-memory data giving each of
its verdicts at least once (the verdict word and the counts it used)."""
import math
import os
import sys
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import thesis_stats as st  # noqa: E402
import thesis_verdicts as tv  # noqa: E402
from thesis_verdicts import Curve, Data  # noqa: E402

SUP, PART, NOT = "supported", "partly supported", "not supported"


class Stats(unittest.TestCase):
    def test_wilson(self):
        lo, hi = st.wilson(5, 10)
        self.assertEqual((round(100 * lo, 1), round(100 * hi, 1)), (23.7, 76.3))
        lo, hi = st.wilson(0, 10)
        self.assertEqual((lo, round(hi, 4)), (0.0, 0.2775))
        lo, hi = st.wilson(10, 10)
        self.assertEqual((round(lo, 4), hi), (0.7225, 1.0))
        self.assertEqual(st.wilson(0, 0), (0.0, 1.0))

    def test_fisher_known_values(self):
        self.assertAlmostEqual(st.fisher_exact(0, 10, 5, 10), 0.0325, places=4)
        self.assertAlmostEqual(st.fisher_exact(5, 10, 0, 10), 0.0325, places=4)
        # the lady tasting tea, 3 of 4 against 1 of 4: two-sided 34/70
        self.assertAlmostEqual(st.fisher_exact(3, 4, 1, 4), 34 / 70, places=12)
        self.assertEqual(st.fisher_exact(3, 10, 3, 10), 1.0)
        self.assertAlmostEqual(st.fisher_exact(0, 10, 10, 10), 2 / 184756, places=15)
        with self.assertRaises(ValueError):
            st.fisher_exact(11, 10, 0, 10)

    def test_mcnemar_known_values(self):
        self.assertEqual(st.mcnemar_exact(0, 0), 1.0)
        self.assertEqual(st.mcnemar_exact(5, 5), 1.0)
        # ten discordant pairs all one way: twice 1/1024
        self.assertEqual(st.mcnemar_exact(10, 0), 2 / 1024)
        self.assertEqual(st.mcnemar_exact(0, 10), 2 / 1024)
        # 1 against 6: twice (1 + 7) / 128
        self.assertEqual(st.mcnemar_exact(1, 6), 0.125)
        with self.assertRaises(ValueError):
            st.mcnemar_exact(-1, 3)

    def test_chi2_known_values(self):
        # the 5% critical values of the chi-square tables
        self.assertAlmostEqual(st.chi2_sf(3.841459, 1), 0.05, places=6)
        self.assertAlmostEqual(st.chi2_sf(16.918978, 9), 0.05, places=6)
        self.assertAlmostEqual(st.chi2_sf(21.665994, 9), 0.01, places=6)
        self.assertAlmostEqual(st.chi2_sf(2.0, 2), math.exp(-1), places=12)  # df 2: exp(-x / 2)
        self.assertEqual(st.chi2_sf(0.0, 3), 1.0)
        with self.assertRaises(ValueError):
            st.chi2_sf(1.0, 0)

    def test_chi2_homogeneity(self):
        # 2 x 2: 10 of 20 against 0 of 20, Pearson's statistic 13.33, df 1
        stat, df, p = st.chi2_homogeneity([10, 0], 20)
        self.assertAlmostEqual(stat, 40 / 3, places=12)
        self.assertEqual(df, 1)
        self.assertAlmostEqual(p, st.chi2_sf(40 / 3, 1), places=15)
        self.assertLess(p, 0.001)
        self.assertEqual(st.chi2_homogeneity([60, 60, 60], 60), (0.0, 2, 1.0))
        self.assertEqual(st.chi2_homogeneity([0, 0], 60), (0.0, 1, 1.0))
        self.assertGreater(st.chi2_homogeneity([30, 31, 29, 30], 60)[2], 0.9)
        with self.assertRaises(ValueError):
            st.chi2_homogeneity([61, 3], 60)

    def test_fisher_counts_tables_as_probable_as_the_observed(self):
        # 1 of 2 against 1 of 2: the tables 0/2-2/2 and 2/2-0/2 are less probable; 1-1 is the observed: p = 1.
        self.assertEqual(st.fisher_exact(1, 2, 1, 2), 1.0)
        # 0 of 2 against 2 of 2: p = 2 * (1/6) = 1/3
        self.assertAlmostEqual(st.fisher_exact(0, 2, 2, 2), 1 / 3, places=12)

    def test_kendall_tau(self):
        self.assertEqual(st.kendall_tau([1, 2, 3], [10, 20, 30]), 1.0)
        self.assertEqual(st.kendall_tau([1, 2, 3], [3, 2, 1]), -1.0)
        self.assertAlmostEqual(st.kendall_tau([1, 2, 2], [1, 2, 3]), 2 / 6 ** 0.5)
        self.assertIsNone(st.kendall_tau([1, 1, 1], [1, 2, 3]))

    def test_counts_behind_printed_percentages(self):
        self.assertEqual(st.count_of(0.35, 20), 7)
        self.assertEqual(st.count_of(0.76, 60), 46)
        self.assertEqual(st.count_of(0.03, 60), 2)
        self.assertFalse(st.printable_as_count(0.76, 60))
        self.assertFalse(st.printable_as_count(0.16, 60))
        self.assertTrue(st.printable_as_count(0.95, 19))
        self.assertTrue(st.printable_as_count(0.84, 19))
        self.assertEqual(st.fitting_n([0.20, 0.0, 0.15, 0.75, 0.95], 30), 20)
        self.assertEqual(st.fitting_n([0.43, 0.37, 0.60, 0.67], 30), 30)

    def test_within_points(self):
        self.assertTrue(st.within_points(0.5, 0.35, 15))
        self.assertFalse(st.within_points(0.5, 0.34, 15))


def rows(e, *spec):
    """{(e, scene, method): (k, n)} from (scene, {method: (k, n)}) pairs."""
    return {(e, s, m): kn for s, cells in spec for m, kn in cells.items()}


def merged(*dicts):
    out = {}
    for d in dicts:
        out.update(d)
    return out


def times(e, scene, g, lo):
    return {(e, scene, "cvfh"): g, (e, scene, "cesf"): g, (e, scene, "shot"): lo, (e, scene, "fpfh"): lo}


def five(cvfh, cesf, shot, fpfh, n=10):
    return {"cvfh": (cvfh, n), "cesf": (cesf, n), "shot": (shot, n), "fpfh": (fpfh, n)}


class Conclusion1(unittest.TestCase):
    def data(self, astra_global, carton_global, global_time, warehouse_local):
        rob = merged(rows("table_4_1", ("warehouse_synthetic", five(2, 1, warehouse_local, 1)),
                          ("table_astra", five(astra_global, 0, 3, 3))),
                     rows("table_4_5", ("table_astra", five(0, carton_global, 4, 4))))
        tm = merged(times("table_4_1", "warehouse_synthetic", global_time, 1.0),
                    times("table_4_1", "table_astra", global_time, 1.0),
                    times("table_4_5", "table_astra", global_time, 1.0))
        return Data(rob=rob, time=tm)

    def test_supported(self):
        v = tv.conclusion_1(self.data(astra_global=8, carton_global=6, global_time=0.2, warehouse_local=9))
        self.assertEqual(v.word, SUP)
        self.assertEqual((v.numbers["time_rows"], v.numbers["global_faster"], v.numbers["smooth_rows"],
                          v.numbers["global_at_least_as_robust"], v.numbers["warehouse_rows"],
                          v.numbers["local_more_robust"]), (3, 3, 2, 2, 1, 1))
        self.assertIn("LS5 1 of 1, milk carton 1 of 1", v.evidence)

    def test_the_carton_counts(self):
        # LS5 row for global, carton row against: 1 of 2 is no majority.
        v = tv.conclusion_1(self.data(astra_global=8, carton_global=1, global_time=0.2, warehouse_local=9))
        self.assertEqual(v.word, PART)
        self.assertEqual(v.numbers["global_at_least_as_robust"], 1)
        self.assertIn("(b) the better global at least as robust in 1 of 2 smooth-object table rows (LS5 1 of 1, milk "
                      "carton 0 of 1): fails", v.evidence)

    def test_not_supported(self):
        v = tv.conclusion_1(self.data(astra_global=1, carton_global=1, global_time=2.0, warehouse_local=0))
        self.assertEqual(v.word, NOT)
        self.assertEqual(v.numbers["parts_holding"], 0)

    def test_nothing_run(self):
        self.assertIsNone(tv.conclusion_1(Data()))


def glob3(cvfh, esf, cesf, n=10):
    return {"cvfh": (cvfh, n), "esf": (esf, n), "cesf": (cesf, n)}


class Conclusion2(unittest.TestCase):
    def test_supported_ties_count_for_cesf(self):
        d = Data(rob=rows("table_4_3", ("a", glob3(5, 0, 6)), ("b", glob3(5, 1, 5)), ("c", glob3(7, 0, 3))))
        v = tv.conclusion_2(d)
        self.assertEqual(v.word, SUP)
        self.assertEqual((v.numbers["rows"], v.numbers["cesf_ahead"], v.numbers["cesf_tied"],
                          v.numbers["cesf_behind"], v.numbers["esf_poor_rows"]), (3, 1, 1, 1, 3))
        self.assertIn("behind in 1 of 3 rows", v.evidence)

    def test_partly_behind_in_most_rows(self):
        # CESF is behind in 3 of 4 rows (one of them at p < 0.05); ESF is poor everywhere.
        d = Data(rob=rows("table_4_1", ("a", glob3(5, 0, 4)), ("b", glob3(10, 0, 0)), ("c", glob3(0, 0, 10))))
        d.rob.update(rows("table_4_4", ("d", glob3(6, 0, 2))))
        v = tv.conclusion_2(d)
        self.assertEqual(v.word, PART)
        self.assertEqual((v.numbers["cesf_behind"], v.numbers["cesf_behind_significant"]), (3, 1))
        self.assertIn("behind in 3 of 4 rows (behind at p < 0.05 in 1): fails", v.evidence)
        self.assertIn("(b) ESF at most 20% in 4 of 4 rows: holds", v.evidence)

    def test_not_supported(self):
        d = Data(rob=rows("table_4_5", ("a", glob3(5, 9, 4)), ("b", glob3(5, 6, 4))))
        v = tv.conclusion_2(d)
        self.assertEqual(v.word, NOT)
        self.assertEqual(v.numbers["esf_poor_rows"], 0)

    def test_other_experiments_are_not_rows(self):
        self.assertIsNone(tv.conclusion_2(Data(rob=rows("fig_4_6", ("a", glob3(5, 0, 6))))))


def crh(skip, with_crh, e_skip="table_4_4", e_crh="table_4_3"):
    """Data of one CRH pair: scene -> (cvfh, cesf) counts of 10, without and with the CRH."""
    rob = {}
    for s in skip:
        rob[(e_skip, s, "cvfh")], rob[(e_skip, s, "cesf")] = (skip[s][0], 10), (skip[s][1], 10)
        rob[(e_crh, s, "cvfh")], rob[(e_crh, s, "cesf")] = (with_crh[s][0], 10), (with_crh[s][1], 10)
    return rob


class Conclusion3(unittest.TestCase):
    def test_supported(self):
        v = tv.conclusion_3(Data(rob=crh({"a": (10, 9), "b": (5, 5)}, {"a": (0, 1), "b": (5, 5)})))
        self.assertEqual(v.word, SUP)
        n = v.numbers["table_4_4"]
        self.assertEqual((n["cells"], n["up"], n["down"], n["up_significant"]), (4, 2, 0, 2))

    def test_evidence_names_the_counts(self):
        v = tv.conclusion_3(Data(rob=crh({"a": (3, 3)}, {"a": (5, 5)})))
        self.assertEqual(v.word, NOT)
        self.assertIn("one model view, 50% -> 30% on average over 2 cells, 0 rise (0 at p < 0.05), 2 fall (0 at p "
                      "< 0.05): does not help", v.evidence)

    def test_not_supported_when_more_fall(self):
        # the mean rises (one big rise) but more cells fall than rise
        v = tv.conclusion_3(Data(rob=crh({"a": (10, 4), "b": (4, 4)}, {"a": (0, 5), "b": (5, 5)})))
        self.assertEqual(v.word, NOT)
        self.assertEqual((v.numbers["table_4_4"]["up"], v.numbers["table_4_4"]["down"]), (1, 3))


THESIS_4_9_TRANSLATION = (8.46, 5.69, 20.87, 8.30, 13.14)
THESIS_4_9_ROTATION = (0.0004, 0.0005, 0.0042, 0.0023, 0.0095)


def registration(rob, rot, trans=THESIS_4_9_TRANSLATION):
    meth = ("icp", "icp_lm", "icp_plane", "gicp", "ndt")
    return Data(rob={("table_4_9", "w", m): (k, 10) for m, k in zip(meth, rob)},
                accuracy={("table_4_9", "w", m): (t, r) for m, t, r in zip(meth, trans, rot)},
                registration_only={"table_4_9", "fig_4_12"})


class Conclusion4(unittest.TestCase):
    def test_the_thesis_own_table_is_supported(self):
        # Table 4.9 of the thesis: ICP lowest in rotation (third in translation), ICP-plane most robust
        v = tv.conclusion_4(registration((19, 16, 19, 16, 16), THESIS_4_9_ROTATION))
        self.assertEqual(v.word, SUP)
        self.assertEqual(v.numbers["most_robust_table"], ["icp", "icp_plane"])
        self.assertIn("translation: icp 8.46 mm, icp_lm 5.69 mm", v.evidence)

    def test_partly_when_icp_plane_is_not_most_robust(self):
        v = tv.conclusion_4(registration((10, 8, 9, 8, 8), THESIS_4_9_ROTATION))
        self.assertEqual(v.word, PART)
        self.assertFalse(v.numbers["icp_plane_most_robust"])

    def test_not_supported_when_icp_is_not_most_accurate_in_rotation(self):
        v = tv.conclusion_4(registration((9, 8, 10, 8, 8), (0.0005, 0.0004, 0.0042, 0.0023, 0.0095)))
        self.assertEqual(v.word, NOT)
        self.assertEqual((v.numbers["lowest"], v.numbers["icp_plane_most_robust"]), (["icp_lm"], True))

    def test_figure_4_12_pooled(self):
        d = registration((10, 10, 10, 10, 10), (0.0001, 0.0002, 0.001, 0.0002, 0.0009))
        d.curves = [Curve("fig_4_12", "w", "icp", {0.0: (10, 10, 0.1), 2.0: (10, 10, 0.1)}),
                    Curve("fig_4_12", "w", "icp_plane", {0.0: (10, 10, 0.1), 2.0: (9, 10, 0.1)})]
        v = tv.conclusion_4(d)
        self.assertEqual(v.word, PART)
        self.assertEqual(v.numbers["most_robust_figure"], ["icp"])
        self.assertIn("icp 20/20, icp_plane 19/20", v.evidence)


class Conclusion5(unittest.TestCase):
    def test_supported(self):
        d = Data(time={("table_4_1", "a", "cvfh"): 0.12, ("table_4_1", "a", "shot"): 14.0,
                       ("table_4_9", "w", "icp"): 0.02}, registration_only={"table_4_9"})
        v = tv.conclusion_5(d)
        self.assertEqual(v.word, SUP)
        self.assertEqual((v.numbers["cells"], v.numbers["at_30fps"]), (2, 0))

    def test_not_supported_by_a_figure_point(self):
        d = Data(time={("table_4_1", "a", "cvfh"): 0.12},
                 curves=[Curve("fig_4_6", "a", "cvfh", {1: (5, 10, 0.021), 2: (5, 10, 0.05)})])
        v = tv.conclusion_5(d)
        self.assertEqual(v.word, NOT)
        self.assertEqual((v.numbers["cells"], v.numbers["at_30fps"]), (3, 1))
        self.assertIn("fig_4_6 a cvfh at 1 0.021 s", v.evidence)


def noise_curves(up, down, flat, n=10):
    """Curves of Figure 4.7: `up` from 0/n to 8/n, `down` from 8/n to 0/n, `flat` 5/n -> 6/n (within noise)."""
    out = []
    for i, (a, b) in enumerate([(0, 8)] * up + [(8, 0)] * down + [(5, 6)] * flat):
        out.append(Curve("fig_4_7_local" if i % 2 else "fig_4_11_global", "s%d" % i, "fpfh",
                         {0.0: (a, n, 1.0), 2.0: (b, n, 1.0), 5.0: (1, n, 1.0)}))
    return out


class Conclusion6(unittest.TestCase):
    def test_supported(self):
        v = tv.conclusion_6(Data(curves=noise_curves(up=2, down=0, flat=1)))
        self.assertEqual(v.word, SUP)
        self.assertEqual((v.numbers["up"], v.numbers["down"], v.numbers["flat"]), (2, 0, 1))

    def test_partly(self):
        v = tv.conclusion_6(Data(curves=noise_curves(up=1, down=0, flat=3)))
        self.assertEqual(v.word, PART)

    def test_two_up_three_down_sixteen_flat_is_not_supported(self):
        v = tv.conclusion_6(Data(curves=noise_curves(up=2, down=3, flat=16)))
        self.assertEqual(v.word, NOT)
        self.assertEqual((v.numbers["curves"], v.numbers["up"], v.numbers["down"], v.numbers["flat"]),
                         (21, 2, 3, 16))
        self.assertIn("21 curves: 2 up, 3 down, 16 flat at p < 0.05", v.evidence)

    def test_changes_within_noise_are_flat(self):
        # 18 curves one image higher at 2 mm: more than half higher in direction, none significant
        v = tv.conclusion_6(Data(curves=noise_curves(up=0, down=0, flat=18)))
        self.assertEqual(v.word, NOT)
        self.assertEqual((v.numbers["higher"], v.numbers["up"]), (18, 0))

    def test_other_figures_are_left_out(self):
        self.assertIsNone(tv.conclusion_6(Data(curves=[Curve("fig_4_6", "a", "cvfh", {0.0: (1, 5, 1.0),
                                                                                          2.0: (5, 5, 1.0)})])))


def family(fig, scene, g, lo, n=10):
    """Global and local curves of one figure and scene set: g, lo correct of n at each of two levels."""
    return [Curve(fig + "_global", scene, m, {0.0: (g, n, 1.0), 5.0: (g, n, 1.0)}) for m in tv.GLOBAL] + \
        [Curve(fig + "_local", scene, m, {0.0: (lo, n, 1.0), 5.0: (lo, n, 1.0)}) for m in tv.LOCAL]


class Conclusion7(unittest.TestCase):
    def test_supported(self):
        v = tv.conclusion_7(Data(curves=family("fig_4_7", "w", 8, 2) + family("fig_4_11", "w", 6, 5)))
        self.assertEqual((v.word, v.numbers["rows"], v.numbers["global_higher"]), (SUP, 2, 2))
        self.assertIn("Figure 4.7 (LS5) w: global 32/40 (80%) vs local 8/40 (20%)", v.evidence)

    def test_partly(self):
        v = tv.conclusion_7(Data(curves=family("fig_4_7", "w", 8, 2) + family("fig_4_7", "t", 2, 8)))
        self.assertEqual((v.word, v.numbers["global_higher"]), (PART, 1))

    def test_not_supported(self):
        v = tv.conclusion_7(Data(curves=family("fig_4_11", "w", 2, 9)))
        self.assertEqual(v.word, NOT)


class All(unittest.TestCase):
    def test_seven_rules_each_printed(self):
        found = tv.evaluate(Data())
        self.assertEqual([c for c, _t, _r, _v in found], ["C1", "C2", "C3", "C4", "C5", "C6", "C7"])
        self.assertTrue(all(v is None for _c, _t, _r, v in found))
        self.assertEqual(set(tv.RULES), {"C1", "C2", "C3", "C4", "C5", "C6", "C7"})
        for rule in tv.RULES.values():
            self.assertIn("Supported", rule)


if __name__ == "__main__":
    unittest.main()
