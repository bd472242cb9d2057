"""scripts/real_diagnosis.py: what became of each target (found, a correct
hypothesis ranked or chosen, near, elsewhere, none) counted from records
checked against the record schema, a variant's change, the oracle's rows
and counts from posebench's --explain answers (a stand-in posebench here),
and exit 2 naming the file for a folder without records or an answer that
is not JSON."""
import contextlib
import copy
import io
import json
import os
import stat
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
RAW = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fixtures", "raw")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import real_diagnosis as rd  # noqa: E402


def run(*argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = rd.main(list(argv))
    return code, out.getvalue(), err.getvalue()


def fixture_records():
    with open(os.path.join(RAW, "table_4_1", "records.jsonl")) as f:
        recs = [json.loads(line) for line in f if line.strip()]
    ok = next(r for r in recs if r["status"] == "ok")
    none = next(r for r in recs if r["status"] == "no_hypothesis")
    return ok, none


def stand_in(folder, text):
    """An executable `posebench` in folder that runs `text` (Python)."""
    path = os.path.join(folder, "posebench")
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, os.stat(path).st_mode | stat.S_IEXEC)
    return path


def target(ok, key, mssd, t, rank):
    """A record of `ok`'s form: diameter 200, MSSD mssd, translation t, correct_rank rank."""
    r = copy.deepcopy(ok)
    r["key"] = key
    r["bop"]["mssd_mm"] = mssd
    r["errors"]["translation_mm_plain"] = t
    r["correct_rank"] = rank
    return r


class Stages(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        ok, none = fixture_records()
        self.base = os.path.join(self.tmp.name, "base")
        self.variant = os.path.join(self.tmp.name, "variant")
        os.makedirs(self.base)
        os.makedirs(self.variant)
        base = [target(ok, "a", 10, 10, 0),      # found, chosen
                target(ok, "b", 80, 30, 2),      # near (30 < 0.25 x 200), a correct hypothesis ranked 2
                target(ok, "c", 900, 700, -1),   # elsewhere (700 > 200), none ranked
                target(ok, "d", 300, 120, -1),   # between
                dict(none, key="e")]             # no hypothesis
        variant = [target(ok, "a", 10, 10, 0), target(ok, "b", 10, 5, 0), target(ok, "c", 900, 700, 1),
                   target(ok, "d", 300, 120, -1), dict(none, key="e")]
        for folder, recs in ((self.base, base), (self.variant, variant)):
            with open(os.path.join(folder, "records.jsonl"), "w") as f:
                f.writelines(json.dumps(r) + "\n" for r in recs)

    def tearDown(self):
        self.tmp.cleanup()

    def test_each_target_counted_once_by_its_fate(self):
        counts, seconds = rd.stage_counts(self.base)
        c = counts[("table_synthetic", "cvfh")]
        self.assertEqual((c["n"], c["found"], c["near"], c["elsewhere"], c["between"], c["none"]), (5, 1, 1, 1, 1, 1))
        self.assertEqual((c["hypothesis"], c["chosen"]), (2, 1))
        self.assertEqual(len(seconds[("table_synthetic", "cvfh")]), 4)  # the ok ones

    def test_the_table_gives_the_variants_change(self):
        code, out, err = run("stages", self.base, "--variant", f"fixed={self.variant}")
        self.assertEqual(code, 0, err)
        row = [line for line in out.splitlines() if line.startswith("| table_synthetic | cvfh |")][0]
        cells = [c.strip() for c in row.strip("|").split("|")]
        self.assertEqual(cells[2:9], ["5", "1", "2", "1", "1", "1", "1"])
        self.assertEqual(cells[10], "2 (+1) / 3 / 2")

    def test_a_folder_without_records_exits_2_naming_it(self):
        empty = os.path.join(self.tmp.name, "empty")
        os.makedirs(empty)
        code, _, err = run("stages", empty)
        self.assertEqual(code, 2)
        self.assertIn(empty, err)

    def test_a_broken_record_exits_2_naming_file_and_line(self):
        with open(os.path.join(self.base, "records.jsonl"), "a") as f:
            f.write('{"key": "x"}\n')
        code, _, err = run("stages", self.base)
        self.assertEqual(code, 2)
        self.assertIn("records.jsonl", err)
        self.assertIn("line 6", err)


STUB = """#!/usr/bin/env python3
import json, sys
a = sys.argv
obj = int(a[a.index("--object") + 1])
if obj == 3:
    print("not json")
    sys.exit(1)
# Object 1: chosen right, the GT (refined 2 mm along z) would rank first.
# Object 2: chosen wrong, the GT (turned 90 deg about z) would rank 2 of 3.
R = [1, 0, 0, 0, 1, 0, 0, 0, 1]
Rz = [0, -1, 0, 1, 0, 0, 0, 0, 1]
if obj == 1:
    ans = {"errors": {"translation_mm": 1.5, "correct": True},
           "ranked": [{"verification": 90, "errors": {"translation_mm": 1.5, "rotation_deg": 1}},
                      {"verification": 50, "errors": {"translation_mm": 300, "rotation_deg": 90}}],
           "ground_truth_refined": {"would_rank": 0, "verification": 80, "R": R, "t": [0, 0, 702]}}
else:
    # Two wrong hypotheses and a right one (2 mm, 10 deg) above the GT.
    ans = {"errors": {"translation_mm": 400.0, "correct": False},
           "ranked": [{"verification": 90, "errors": {"translation_mm": 400, "rotation_deg": 10}},
                      {"verification": 85, "errors": {"translation_mm": 2, "rotation_deg": 10}},
                      {"verification": 84, "errors": {"translation_mm": 20, "rotation_deg": 60}}],
           "ground_truth_refined": {"would_rank": 3, "verification": 70, "R": Rz, "t": [100, 0, 800]}}
print(json.dumps(ans))
"""


class Oracle(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        d = self.ds = os.path.join(self.tmp.name, "ds")
        os.makedirs(os.path.join(d, "test", "000001"))
        gt = {"0": [{"obj_id": 1, "cam_R_m2c": [1, 0, 0, 0, 1, 0, 0, 0, 1], "cam_t_m2c": [0, 0, 700]},
                    {"obj_id": 2, "cam_R_m2c": [1, 0, 0, 0, 1, 0, 0, 0, 1], "cam_t_m2c": [100, 0, 800]}],
              "1": [{"obj_id": 3, "cam_R_m2c": [1, 0, 0, 0, 1, 0, 0, 0, 1], "cam_t_m2c": [0, 0, 700]}]}
        with open(os.path.join(d, "test", "000001", "scene_gt.json"), "w") as f:
            json.dump(gt, f)
        self.targets = [{"scene_id": 1, "im_id": 0, "obj_id": 1, "inst_count": 1},
                        {"scene_id": 1, "im_id": 0, "obj_id": 2, "inst_count": 1}]
        with open(os.path.join(d, "test_targets_bop19.json"), "w") as f:
            json.dump(self.targets, f)
        self.stub = stand_in(self.tmp.name, STUB)

    def tearDown(self):
        self.tmp.cleanup()

    def test_rows_and_counts(self):
        code, out, err = run("oracle", "--dataset", self.ds, "--method", "ppf", "--posebench", self.stub)
        self.assertEqual(code, 0, err)
        self.assertIn("| 1 | 0 | 1 | 2 | yes | 0 of 2 | 0 | 2.0 | 0.0 |", out)
        self.assertIn("| 1 | 0 | 2 | 400 | no | 3 of 3 | 2 | 0.0 | 90.0 |", out)
        self.assertIn("ppf: 2 targets; chosen correct 1; the refined ground truth would rank above every wrong "
                      "hypothesis 1; "
                      "refinement turned the ground truth by over 5 deg 1 (moved it by 1.0 mm at the median)", out)

    def test_image_stride_keeps_every_nth_image_of_each_scene_in_order(self):
        targets = self.targets + [{"scene_id": 1, "im_id": 1, "obj_id": 3, "inst_count": 1}]
        with open(os.path.join(self.ds, "test_targets_bop19.json"), "w") as f:
            json.dump(targets, f)
        # Stride 2 keeps image 0 only: object 3 (whose answer is not JSON) is never asked.
        code, out, err = run("oracle", "--dataset", self.ds, "--method", "ppf", "--posebench", self.stub,
                             "--image-stride", "2")
        self.assertEqual(code, 0, err)
        self.assertIn("2 targets", out)
        # Every image: object 3's answer is not JSON, exit 2 naming the command.
        code, _, err = run("oracle", "--dataset", self.ds, "--method", "ppf", "--posebench", self.stub)
        self.assertEqual(code, 2)
        self.assertIn("--object 3", err)
        self.assertIn("not JSON", err)


SCORE_STUB = """#!/usr/bin/env python3
import json, os, sys
a = sys.argv
out = a[a.index("--out") + 1]
targets = json.load(open(a[a.index("--targets") + 1]))
os.makedirs(out, exist_ok=True)
ar = 0.5 if "ppf" in a[2] else 0.25
json.dump({"bop19_average_recall": ar, "bop19_average_recall_mssd": ar, "bop19_average_recall_mspd": ar,
           "bop19_average_recall_vsd": ar, "targets_count": len(targets)}, open(os.path.join(out, "scores.json"), "w"))
"""


class AverageRecall(unittest.TestCase):
    """`ar` scores each results file on the targets of the images the run took."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        ok, _ = fixture_records()
        self.run_dir = os.path.join(self.tmp.name, "run")
        os.makedirs(os.path.join(self.run_dir, "bop"))
        with open(os.path.join(self.run_dir, "records.jsonl"), "w") as f:
            for im in (0, 2):  # the run took images 0 and 2 of the dataset's 0, 1, 2
                r = copy.deepcopy(ok)
                r.update(key=f"k{im}", scene="real", scene_id=1, im_id=im)
                f.write(json.dumps(r) + "\n")
        for m in ("ppf", "shot"):
            open(os.path.join(self.run_dir, "bop", f"posebench-{m}-icp_real-test.csv"), "w").close()
        open(os.path.join(self.run_dir, "bop", "posebench-ppf-icp_other-test.csv"), "w").close()
        self.ds = os.path.join(self.tmp.name, "ds")
        os.makedirs(self.ds)
        with open(os.path.join(self.ds, "test_targets_bop19.json"), "w") as f:
            json.dump([{"scene_id": 1, "im_id": im, "obj_id": 5, "inst_count": 1} for im in (0, 1, 2)], f)
        self.stub = stand_in(self.tmp.name, SCORE_STUB)

    def tearDown(self):
        self.tmp.cleanup()

    def test_each_file_of_a_named_scene_on_the_images_run(self):
        code, out, err = run("ar", self.run_dir, "--dataset", f"real={self.ds}", "--posebench", self.stub)
        self.assertEqual(code, 0, err)
        self.assertIn("| posebench-ppf-icp | real | 2 | 0.500 |", out)
        self.assertIn("| posebench-shot-icp | real | 2 | 0.250 |", out)
        self.assertNotIn("other", out)  # no dataset named for that scene

    def test_a_run_without_bop_results_exits_2_naming_the_folder(self):
        os.rename(os.path.join(self.run_dir, "bop"), os.path.join(self.run_dir, "elsewhere"))
        code, _, err = run("ar", self.run_dir, "--dataset", f"real={self.ds}", "--posebench", self.stub)
        self.assertEqual(code, 2)
        self.assertIn("bop", err)


if __name__ == "__main__":
    unittest.main()
