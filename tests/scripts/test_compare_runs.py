"""scripts/compare_runs.py on small record folders: the counts per cell, the
verdict per cell (equal, up, down, significant), cells of one run only, and
exit 2 with the folder named when there are no records."""
import contextlib
import io
import json
import os
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import compare_runs as cr  # noqa: E402


def write(folder, exp, rows):
    os.makedirs(os.path.join(folder, exp), exist_ok=True)
    with open(os.path.join(folder, exp, "records.jsonl"), "w") as f:
        for scene, desc, noise, correct, wall in rows:
            f.write(json.dumps({"scene": scene, "descriptor": desc, "refinement": "icp", "added_noise_mm": noise,
                                "params": {}, "correct": correct, "wall_s": wall}) + "\n")


class CompareRuns(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.before, self.after = (os.path.join(self.tmp.name, d) for d in ("before", "after"))
        # cell A: 10/10 -> 0/10 (significant), cell B: 5/10 -> 6/10, cell C equal, cell D only before
        write(self.before, "exp", [("t", "fpfh", 0.0, True, 2.0)] * 10 + [("t", "shot", 0.0, i < 5, 1.0) for i in range(10)]
              + [("w", "cvfh", 2.0, i < 3, 1.0) for i in range(4)] + [("w", "esf", 2.0, True, 1.0)])
        write(self.after, "exp", [("t", "fpfh", 0.0, False, 1.0)] * 10 + [("t", "shot", 0.0, i < 6, 1.0) for i in range(10)]
              + [("w", "cvfh", 2.0, i < 3, 0.5) for i in range(4)])

    def tearDown(self):
        self.tmp.cleanup()

    def test_counts_and_verdicts(self):
        b, sb = cr.cells(self.before)
        a, sa = cr.cells(self.after)
        self.assertEqual(b[("exp", "t", "fpfh", "icp", 0.0, "{}")], [10, 10])
        self.assertEqual(sb, {"exp": 35.0})
        self.assertEqual(sa, {"exp": 22.0})
        r = cr.compare(b, a)
        self.assertEqual((r["cells"], r["equal"], r["up"], r["down"], r["unmatched"]), (3, 1, 1, 1, 1))
        self.assertEqual((r["correct_before"], r["correct_after"], r["trials"]), (18, 9, 24))
        self.assertEqual([c["cell"][2] for c in r["significant"]], ["fpfh"])
        self.assertAlmostEqual(r["significant"][0]["p"], 2 / 184756, places=12)
        self.assertEqual([c["cell"][2] for c in r["moved"]], ["fpfh", "shot"])

    def test_one_run_folder_and_exit_codes(self):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            code = cr.main([os.path.join(self.before, "exp"), os.path.join(self.after, "exp")])
        self.assertEqual(code, 0)
        self.assertIn("3 cells, 24 trials: correct 18 -> 9; 1 equal, 1 up, 1 down, 1 at p < 0.05", out.getvalue())
        empty = os.path.join(self.tmp.name, "empty")
        os.makedirs(empty)
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = cr.main([self.before, empty])
        self.assertEqual(code, 2)
        self.assertIn(empty, err.getvalue())
        self.assertIn("no records.jsonl", err.getvalue())


if __name__ == "__main__":
    unittest.main()
