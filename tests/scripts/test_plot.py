"""scripts/plot.py: the Wilson band (the same numbers as eval/stats.h), one
line style per scene set and one marker per method, the log time axis only
when times span a decade, the trials note, and a PNG drawn from plot data."""
import os
import struct
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import plot  # noqa: E402


def series(method, scene, times, trials=(10, 10), correct=(5, 10)):
    return {"label": method + " (" + scene + ")", "method": method, "scene": scene, "x": [0, 5],
            "robustness": [c / n for c, n in zip(correct, trials)], "time": list(times),
            "correct": list(correct), "trials": list(trials)}


class Plot(unittest.TestCase):
    def test_wilson(self):
        lo, hi = plot.wilson(5, 10)
        self.assertAlmostEqual(lo, 0.2366, places=4)
        self.assertAlmostEqual(hi, 0.7634, places=4)
        self.assertEqual(plot.wilson(0, 0), (0.0, 1.0))
        lo, hi = plot.wilson(10, 10)
        self.assertAlmostEqual(lo, 0.7225, places=4)
        self.assertAlmostEqual(hi, 1.0, places=12)

    def test_styles_line_per_scene_marker_per_method(self):
        s = [series("cvfh", "astra", [1, 1]), series("esf", "astra", [1, 1]),
             series("cvfh", "kinect", [1, 1]), series("esf", "kinect", [1, 1])]
        st = plot.styles(s)
        self.assertEqual([x[0] for x in st], ["-", "-", "--", "--"])
        self.assertEqual([x[1] for x in st], ["o", "s", "o", "s"])
        self.assertEqual(len(set(st)), 4)

    def test_families_get_line_styles_and_scene_sets_panels(self):
        s = [dict(series("cvfh", "warehouse", [1, 1]), family="global"),
             dict(series("shot", "warehouse", [1, 1]), family="local"),
             dict(series("cvfh", "table", [1, 1]), family="global"),
             dict(series("shot", "table", [1, 1]), family="local")]
        st = plot.styles(s)
        self.assertEqual([x[0] for x in st], ["-", "--", "-", "--"])  # global solid, local dashed
        self.assertEqual([x[1] for x in st], ["o", "s", "o", "s"])
        self.assertEqual([(sc, [x["method"] for x in part]) for sc, part in plot.panels(s)],
                         [("warehouse", ["cvfh", "shot"]), ("table", ["cvfh", "shot"])])
        self.assertEqual(plot.panels(s[:1] and [series("a", "x", [1, 1])])[0][0], "")  # no family: one row

    def test_log_axis_only_across_a_decade(self):
        self.assertFalse(plot.log_time_axis([series("a", "s", [0.1, 0.9])]))
        self.assertTrue(plot.log_time_axis([series("a", "s", [0.1, 0.5]), series("b", "s", [2.0, None])]))
        self.assertFalse(plot.log_time_axis([series("a", "s", [None, None])]))

    def test_trials_note(self):
        self.assertEqual(plot.trials_note([series("a", "s", [1, 1])]), "n = 10 trials per point")
        self.assertEqual(plot.trials_note([series("a", "s", [1, 1], trials=(5, 10), correct=(1, 2))]),
                         "n = 5 to 10 trials per point")

    def test_draws_a_png(self):
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            self.skipTest("python3-matplotlib not installed")
        p = {"name": "robustness_vs_noise", "x_label": "added noise sigma (mm)", "title": "Figure 4.7: test",
             "series": [series("cvfh", "astra", [0.05, 3.0]), series("esf", "astra", [0.2, 0.3])]}
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "p.png")
            plot.draw(p, out)
            with open(out, "rb") as f:
                head = f.read(24)
            self.assertEqual(head[:8], b"\x89PNG\r\n\x1a\n")
            w, h = struct.unpack(">II", head[16:24])
            self.assertEqual(w, 1320)  # 12 x 4.6 inches at 110 dpi
            self.assertIn(h, (505, 506))


if __name__ == "__main__":
    unittest.main()
