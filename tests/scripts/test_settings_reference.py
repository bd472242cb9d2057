"""scripts/settings_reference.py: each setting's doc comes from the comment
beside its member (with its continuation lines) or the block above it, the
struct is found by its fields() keys, the page lists key, type, default and
what it accepts, --check exits 1 for a stale page and 0 for a current one,
and an unreadable schema exits 2."""
import contextlib
import io
import json
import os
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import settings_reference as sr  # noqa: E402

HEADER = """
struct DemoSettings {
  double voxel_mm = 10.0;   // downsampling voxel,
                            // in mm
  // Which model cloud counts:
  // the view or the merged one.
  std::string model = "view";
  int unlisted = 3;         // not in fields(): left out
  template <class S, class F>
  static void fields(S& s, F& f) {
    f("voxel_mm", s.voxel_mm, fields::length(fields::positive()));
    f("model", s.model, fields::one_of({"view", "merged"}));
  }
};
"""

SCHEMA = {
    "descriptor": {"type": "string", "default": "fpfh", "accepts": "one of: fpfh, ppf"},
    "refinement": {"type": "string", "default": "icp", "accepts": "one of: none, icp"},
    "seed": {"type": "integer", "default": 1, "accepts": ">= 0"},
    "sections": [{"name": "demo", "fields": [
        {"key": "voxel_mm", "type": "number", "default": "0.05d", "accepts": "> 0 (mm, or a fraction of the diameter: 0.05d)"},
        {"key": "model", "type": "string", "default": "view", "accepts": "one of: view, merged"}]}],
}


def run(*argv):
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = sr.main(list(argv))
    return code, err.getvalue()


class SettingsReference(unittest.TestCase):
    def test_docs_from_the_comments_beside_and_above(self):
        docs = sr.struct_docs(HEADER)
        self.assertEqual(list(docs), [frozenset({"voxel_mm", "model"})])
        d = docs[frozenset({"voxel_mm", "model"})]
        self.assertEqual(d["voxel_mm"], "downsampling voxel, in mm")
        self.assertEqual(d["model"], "Which model cloud counts: the view or the merged one.")

    def test_page_lists_every_field_and_check_compares(self):
        with tempfile.TemporaryDirectory() as tmp:
            os.makedirs(os.path.join(tmp, "src"))
            with open(os.path.join(tmp, "src", "demo.h"), "w") as fh:
                fh.write(HEADER)
            schema = os.path.join(tmp, "schema.json")
            with open(schema, "w") as fh:
                json.dump(SCHEMA, fh)
            page = os.path.join(tmp, "settings.md")
            self.assertEqual(run("--schema", schema, "--src", os.path.join(tmp, "src"), "--out", page)[0], 0)
            text = open(page).read()
            self.assertIn("## demo", text)
            self.assertIn("- `voxel_mm`: number, default `0.05d`; > 0 (mm, or a fraction of the diameter: 0.05d). "
                          "downsampling voxel, in mm", text)
            self.assertIn("- `model`: string, default `view`; one of: view, merged.", text)
            self.assertIn("- `seed`: integer, default `1`; >= 0", text)
            self.assertEqual(run("--schema", schema, "--src", os.path.join(tmp, "src"), "--check", page)[0], 0)
            with open(page, "a") as fh:
                fh.write("stale\n")
            code, err = run("--schema", schema, "--src", os.path.join(tmp, "src"), "--check", page)
            self.assertEqual(code, 1)
            self.assertIn("out of date", err)

    def test_unreadable_schema_exits_two(self):
        with tempfile.TemporaryDirectory() as tmp:
            bad = os.path.join(tmp, "bad.json")
            with open(bad, "w") as fh:
                fh.write("{not json")
            code, err = run("--schema", bad, "--out", os.path.join(tmp, "x.md"))
            self.assertEqual(code, 2)
            self.assertIn("cannot read the settings schema", err)


if __name__ == "__main__":
    unittest.main()
