"""scripts/thesis_report.py: fixture results folders in (two experiments as
`posebench run` and `posebench report` write them, tests/scripts/fixtures/),
README rows out; strict records (a misspelt key is exit code 2 naming file,
line and key); the carton's faces row from the records' judgements."""
import contextlib
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FIXTURES = os.path.join(os.path.dirname(__file__), "fixtures")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import thesis_report  # noqa: E402


class Run:
    """Copies the fixtures to a temporary OUT, applies `edit`, writes the README."""

    def __init__(self, edit=None, experiments=("table_4_1", "table_4_5")):
        self.tmp = tempfile.mkdtemp()
        self.out = os.path.join(self.tmp, "thesis")
        shutil.copytree(FIXTURES, self.out)
        if edit:
            edit(os.path.join(self.out, "raw"))
        err = io.StringIO()
        env = dict(os.environ, POSEBENCH="")  # the built-in schema copy
        old = os.environ.copy()
        os.environ.clear()
        os.environ.update(env)
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                self.code = thesis_report.main([self.out] + list(experiments))
        finally:
            os.environ.clear()
            os.environ.update(old)
        self.err = err.getvalue()
        path = os.path.join(self.out, "README.md")
        self.lines = []
        if os.path.exists(path):
            with open(path) as f:
                self.lines = f.read().splitlines()
        shutil.rmtree(self.tmp)


def rewrite_records(raw, name, change):
    path = os.path.join(raw, name, "records.jsonl")
    with open(path) as f:
        records = [json.loads(line) for line in f]
    for r in records:
        change(r)
    with open(path, "w") as f:
        f.write("".join(json.dumps(r) + "\n" for r in records))


class Readme(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.run_ = Run()

    def test_exit_code_zero(self):
        self.assertEqual(self.run_.code, 0, self.run_.err)

    def test_experiments_table_times_and_loads_from_runs_jsonl(self):
        # table_4_1: two invocations, 30.5 s + 12.0 s, loads 1.5 and 2.0.
        self.assertIn("| Table 4.1 | `configs/thesis/table_4_1.yaml` | 2 | 4 | no_hypothesis 1, ok 3 | 0m42s | "
                      "1.5/2.0 |", self.run_.lines)
        self.assertIn("| Table 4.5 | `configs/thesis/table_4_5.yaml` | 2 | 4 | no_hypothesis 1, ok 3 | 0m20s | 0.5 |",
                      self.run_.lines)
        self.assertIn("| **total** | | | 8 | | **1m02s** | |", self.run_.lines)

    def test_table_rows_come_from_the_report_with_the_thesis_beside(self):
        # cvfh: 1 of 2 correct (thesis 43%), fpfh: 2 of 2 (thesis 67%), Table 4.1 table synthetic.
        self.assertIn("| table_synthetic | robustness | 50% (43%) | 100% (67%) |", self.run_.lines)

    def test_carton_faces_row_from_the_records_judgements(self):
        # cvfh: 1 of 2 correct with the half turn, 2 of 2 faces on faces; fpfh: 0 and 0.
        self.assertIn("| table_astra | half turn only | 50% | 0% |", self.run_.lines)
        self.assertIn("|  | faces on faces (thesis) | 100% (31%) | 0% (16%) |", self.run_.lines)


class Carton(unittest.TestCase):
    def test_records_without_judgements_give_a_dash_and_a_note(self):
        def drop(raw):
            rewrite_records(raw, "table_4_5", lambda r: r.pop("judgements", None))
        run = Run(drop)
        self.assertEqual(run.code, 0, run.err)
        self.assertIn("|  | faces on faces (thesis) | - | - |", run.lines)
        self.assertTrue(any("re-run table_4_5" in line for line in run.lines))


class StrictRecords(unittest.TestCase):
    def test_misspelt_key_is_exit_2_naming_file_line_and_key(self):
        def misspell(raw):
            path = os.path.join(raw, "table_4_1", "records.jsonl")
            with open(path) as f:
                lines = f.read().splitlines()
            r = json.loads(lines[1])
            r["statsu"] = r.pop("status")
            lines[1] = json.dumps(r)
            with open(path, "w") as f:
                f.write("\n".join(lines) + "\n")
        run = Run(misspell)
        self.assertEqual(run.code, 2)
        self.assertIn("table_4_1/records.jsonl: line 2: unknown key 'statsu'", run.err)

    def test_missing_required_key_is_exit_2(self):
        def drop(raw):
            rewrite_records(raw, "table_4_5", lambda r: r.pop("seed"))
        run = Run(drop)
        self.assertEqual(run.code, 2)
        self.assertIn("table_4_5/records.jsonl: line 1: missing required key 'seed'", run.err)


class Schema(unittest.TestCase):
    def test_the_copy_matches_the_binarys_schema(self):
        binary = os.environ.get("POSEBENCH", os.path.join(ROOT, "build", "posebench"))
        if not os.access(binary, os.X_OK):
            self.skipTest("no posebench binary at %s (build it, or set POSEBENCH)" % binary)
        r = subprocess.run([binary, "schema", "record"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(thesis_report.binary_schema(binary), thesis_report.RECORD_SCHEMA)


if __name__ == "__main__":
    unittest.main()
