"""scripts/structure_check.py: the limits it enforces, on small fixtures, and
on the project's own src/ (so CI fails when a function outgrows them)."""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import structure_check  # noqa: E402


def write(d, name, text):
    path = os.path.join(d, name)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    return path


class Functions(unittest.TestCase):
    def test_finds_functions_and_their_lengths(self):
        text = ("namespace a {\n"            # 1
                "int f(int x) {\n"            # 2
                "  if (x) {\n"                # 3
                "    return 1;\n"             # 4
                "  }\n"                       # 5
                "  return 2;\n"               # 6
                "}\n"                         # 7
                "struct S {\n"                # 8
                "  void g() const { }\n"      # 9
                "};\n"                        # 10
                "}  // namespace a\n")
        self.assertEqual(structure_check.functions(text), [("f", 2, 7), ("g", 9, 9)])

    def test_braces_in_strings_and_comments_do_not_count(self):
        text = 'void h() {\n  const char* s = "{{";  // }\n  /* { */\n}\n'
        self.assertEqual(structure_check.functions(text), [("h", 1, 4)])

    def test_qualifiers_and_long_blank_runs_after_a_parenthesis(self):
        # Qualifiers and a trailing return type still make a signature; a
        # parenthesis followed by a long run of spaces (a blanked comment)
        # and then something else is no signature, and is decided at once
        # (a pattern that backtracks over every split of the run takes
        # minutes on src/recognition/local/match_kernels.cpp).
        text = ("auto f(int x) const noexcept -> int {\n"
                "  return x;\n"
                "}\n"
                "#if defined(A)" + " " * 3000 + "/* a long comment */ " + "x" + " " * 3000 + "\n"
                "struct S {\n"
                "};\n")
        self.assertEqual(structure_check.functions(text), [("f", 1, 3)])

    def test_control_statements_and_initializers_are_not_functions(self):
        text = "int v[] = {1, 2};\nvoid k() {\n  for (int i = 0; i < 2; ++i) {\n  }\n}\n"
        self.assertEqual(structure_check.functions(text), [("k", 2, 5)])


class Limits(unittest.TestCase):
    def test_long_function_and_pcl_header_are_reported(self):
        with tempfile.TemporaryDirectory() as d:
            write(d, "ok.cpp", "void f() {\n}\n")
            write(d, "long.cpp", "void g() {\n" + "  x();\n" * 30 + "}\n")
            write(d, "big.h", "// x\n" * 60)
            write(d, "api.h", "#include <pcl/point_types.h>\n")
            write(d, "recognition/pcl_glue.h", "#include <pcl/point_types.h>\n")
            problems = structure_check.check([d], max_function=20)
            text = "\n".join(problems)
            self.assertIn("long.cpp:1: function g is 32 lines (limit 20)", text)
            self.assertNotIn("big.h", text)  # a file's length is no limit
            self.assertIn("api.h: a header includes PCL", text)
            self.assertNotIn("pcl_glue.h", text)
            self.assertNotIn("ok.cpp", text)
            self.assertEqual(len(problems), 2)

    def test_the_project_source_is_within_the_limits(self):
        r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "structure_check.py"),
                            os.path.join(ROOT, "src")], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)


if __name__ == "__main__":
    unittest.main()
