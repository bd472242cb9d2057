"""scripts/compare_runs.py: the counts per cell read from the fixture results
folders (records checked against the record schema), the verdict per cell
(equal, up, down, significant, in one run only), and exit 2 naming the file,
line and key for a broken record, or the folder when it has no records."""
import contextlib
import io
import json
import os
import shutil
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
RAW = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fixtures", "raw")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import compare_runs as cr  # noqa: E402


def run(*argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cr.main(list(argv))
    return code, out.getvalue(), err.getvalue()


class CompareRuns(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.before = os.path.join(self.tmp.name, "before")
        self.after = os.path.join(self.tmp.name, "after")
        shutil.copytree(RAW, self.before)
        shutil.copytree(RAW, self.after)

    def tearDown(self):
        self.tmp.cleanup()

    def edit(self, folder, exp, change):
        """Rewrites every record of `exp` in `folder` by change(record) (None drops it)."""
        path = os.path.join(folder, exp, "records.jsonl")
        with open(path) as f:
            records = [json.loads(line) for line in f if line.strip()]
        with open(path, "w") as f:
            for r in records:
                r = change(r)
                if r is not None:
                    f.write(json.dumps(r) + "\n")

    def test_cells_of_the_fixture_records(self):
        counts, seconds = cr.cells(self.before)
        self.assertEqual(counts[("table_4_1", "table_synthetic", 1, "fpfh", "icp", 0.0, "{}")], [2, 2])
        self.assertEqual(counts[("table_4_1", "table_synthetic", 1, "cvfh", "icp", 0.0, "{}")], [1, 2])
        self.assertEqual(counts[("fig_4_12", "warehouse_synthetic", 1, "none", "icp_plane", 2.0, "{}")], [1, 2])
        self.assertEqual(set(seconds), {"table_4_1", "table_4_5", "fig_4_12"})
        # One run's folder alone: named by its folder.
        one, _ = cr.cells(os.path.join(self.before, "table_4_1"))
        self.assertEqual({k[0] for k in one}, {"table_4_1"})

    def test_a_cell_per_object(self):
        # An `object: all` run: the same experiment, scene and method, two
        # objects, two cells; one object losing all is significant alone.
        def obj(r):
            return dict(r, obj_id=7) if r["descriptor"] == "cvfh" else r
        self.edit(self.before, "table_4_1", obj)
        counts, _ = cr.cells(self.before)
        self.assertEqual(counts[("table_4_1", "table_synthetic", 7, "cvfh", "icp", 0.0, "{}")], [1, 2])
        self.assertNotIn(("table_4_1", "table_synthetic", 1, "cvfh", "icp", 0.0, "{}"), counts)
        before = {("e", "s", 1, "ppf", "icp", 0.0, "{}"): [10, 10], ("e", "s", 2, "ppf", "icp", 0.0, "{}"): [0, 10]}
        after = {("e", "s", 1, "ppf", "icp", 0.0, "{}"): [0, 10], ("e", "s", 2, "ppf", "icp", 0.0, "{}"): [10, 10]}
        r = cr.compare(before, after)  # pooled 10 -> 10; per object, both significant
        self.assertEqual((r["correct_before"], r["correct_after"], len(r["significant"])), (10, 10, 2))
        self.assertEqual(cr.name(r["significant"][0]["cell"]), "e s obj 1 ppf+icp noise 0")
        self.assertEqual(cr.name(("e", "s", None, "ppf", "icp", 0.0, "{}")), "e s ppf+icp noise 0")
        # A failed trial's record without obj_id (the schema asks for it on
        # ok records only) is read, in a cell without an object.
        self.edit(self.after, "table_4_1",
                  lambda r: r if r["status"] == "ok" else {k: v for k, v in r.items() if k != "obj_id"})
        counts, _ = cr.cells(self.after)
        self.assertTrue(any(k[0] == "table_4_1" and k[2] is None for k in counts))
        code, _, _ = run(self.before, self.after)
        self.assertEqual(code, 0)

    def test_verdicts(self):
        before = {("e", "s", 1, "a", "icp", 0.0, "{}"): [10, 10], ("e", "s", 1, "b", "icp", 0.0, "{}"): [5, 10],
                  ("e", "s", 1, "c", "icp", 0.0, "{}"): [3, 4], ("e", "s", 1, "d", "icp", 0.0, "{}"): [1, 1]}
        after = {("e", "s", 1, "a", "icp", 0.0, "{}"): [0, 10], ("e", "s", 1, "b", "icp", 0.0, "{}"): [6, 10],
                 ("e", "s", 1, "c", "icp", 0.0, "{}"): [3, 4]}
        r = cr.compare(before, after)
        self.assertEqual((r["cells"], r["equal"], r["up"], r["down"], r["unmatched"]), (3, 1, 1, 1, 1))
        self.assertEqual((r["correct_before"], r["correct_after"], r["trials"]), (18, 9, 24))
        self.assertEqual([c["cell"][3] for c in r["significant"]], ["a"])
        self.assertAlmostEqual(r["significant"][0]["p"], 2 / 184756, places=12)
        self.assertEqual([c["cell"][3] for c in r["moved"]], ["a", "b"])

    def test_printed_totals(self):
        # The after run loses every correct fpfh record of table_4_1.
        self.edit(self.after, "table_4_1",
                  lambda r: dict(r, correct=False) if r["descriptor"] == "fpfh" and "correct" in r else r)
        code, out, _ = run(self.before, self.after)
        self.assertEqual(code, 0)
        self.assertIn("1 down", out)
        self.assertIn("moved: table_4_1 table_synthetic obj 1 fpfh+icp noise 0 2/2 -> 0/2", out)
        # Paired by trial: the two fpfh trials correct before only; 2 of 2 discordant pairs one way.
        self.assertIn("correct before only 2, after only 0; McNemar's exact test p = 0.5", out)

    def test_trials_paired_by_experiment_and_key(self):
        before = {("e", "k1"): True, ("e", "k2"): False, ("e", "k3"): True, ("f", "k1"): False, ("e", "old"): True}
        after = {("e", "k1"): True, ("e", "k2"): True, ("e", "k3"): False, ("f", "k1"): True, ("e", "new"): False}
        pr = cr.paired(before, after)
        self.assertEqual((pr["pairs"], pr["before_only"], pr["after_only"]), (4, 1, 2))
        self.assertEqual(pr["p"], 1.0)
        # The fixture folder against itself: every trial paired, none discordant.
        trials = ({}, {})
        cr.cells(self.before, trials[0])
        cr.cells(self.after, trials[1])
        pr = cr.paired(*trials)
        self.assertEqual((pr["pairs"], pr["before_only"], pr["after_only"], pr["p"]), (len(trials[0]), 0, 0, 1.0))
        self.assertGreater(pr["pairs"], 0)

    def test_broken_record_and_empty_folder_are_exit_2(self):
        self.edit(self.after, "fig_4_12", lambda r: {k: v for k, v in r.items() if k != "scene"})
        code, _, err = run(self.before, self.after)
        self.assertEqual(code, 2)
        self.assertIn(os.path.join(self.after, "fig_4_12", "records.jsonl"), err)
        self.assertIn("line 1", err)
        self.assertIn("scene", err)
        empty = os.path.join(self.tmp.name, "empty")
        os.makedirs(empty)
        code, _, err = run(self.before, empty)
        self.assertEqual(code, 2)
        self.assertIn(empty, err)
        self.assertIn("no records.jsonl", err)


if __name__ == "__main__":
    unittest.main()
