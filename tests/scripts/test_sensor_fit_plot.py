"""scripts/sensor_fit_plot.py: the values it draws, and the figure."""
import json
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import sensor_fit_plot as sfp  # noqa: E402

try:
    import matplotlib  # noqa: F401  (the plots need it; Debian's python3-matplotlib)
    HAVE_MATPLOTLIB = True
except ImportError:
    HAVE_MATPLOTLIB = False


def bin_(lo, hi, n, missing, nearer=0, spread=1.0):
    return {"lo": lo, "hi": hi, "n": n, "missing": missing, "nearer": nearer, "farther": 0, "inliers": n - missing,
            "missing_rate": missing / n, "bias_mm": 0.0, "spread_mm": spread}


def stats():
    return {"all": bin_(0, 1, 1000, 100), "interior_frontal": bin_(0, 1, 500, 10),
            "by_depth": [bin_(500, 750, 600, 60, spread=1.5), bin_(750, 1000, 50, 5, spread=9.0)],
            "by_incidence": [bin_(0, 10, 400, 40, nearer=200)], "by_edge_px": [bin_(0, 0, 300, 90)],
            "by_object": {"3": bin_(0, 1, 1000, 100)},
            "silhouette": [{"d": 0, "n": 10, "object": 7, "farther": 1, "nearer": 0, "missing": 2}],
            "quantization": [{"lo": 500, "hi": 750, "frames": 2, "step_mm": 1.0}],
            "normal_error": [{"lo": 500, "hi": 750, "n": 30, "median_deg": 4.0, "p90_deg": 9.0}]}


class SensorFitPlotTest(unittest.TestCase):
    def test_missing_rate_leaves_out_what_stands_in_front(self):
        self.assertAlmostEqual(sfp.geometric_missing(bin_(0, 10, 400, 40, nearer=200)), 0.2)

    def test_series_skips_thin_bins(self):
        xs, ys, ns = sfp.series(stats(), "by_depth", lambda b: b["spread_mm"], min_n=100)
        self.assertEqual((xs, ys, ns), ([625.0], [1.5], [600]))

    @unittest.skipUnless(HAVE_MATPLOTLIB, "matplotlib is not installed (apt install python3-matplotlib)")
    def test_draws_every_set(self):
        data = {"dataset": "x", "images": 1, "loss": {"base": {"total": 2.0}, "fitted": {"total": 1.0}},
                "real": stats(), "simulated_base": stats(), "simulated_fitted": stats()}
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "sensor_fit.json")
            with open(path, "w") as f:
                json.dump(data, f)
            self.assertEqual(sfp.main(["sensor_fit_plot.py", path, os.path.join(d, "plots")]), 0)
            with open(os.path.join(d, "plots", "sensor_fit.png"), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")


if __name__ == "__main__":
    unittest.main()
