#!/usr/bin/env python3
"""Structure limits of the source tree: function length, and PCL's headers.

    scripts/structure_check.py [--max-function 80] [DIR ...]

Prints every function body in a C++ file (.h/.cpp) over --max-function
lines (from the line of its opening brace to the line of its closing
brace), and every header that includes PCL but is not one of
recognition's private glue headers (src/recognition/**/pcl_*.h), then exits
1 if any, else 0. Default DIR: src.

Functions are found by brace matching with comments, strings and character
literals skipped: a brace opens a function body when the code before it
ends in a parameter list (optionally followed by const, override, noexcept,
a trailing return type or a constructor's initializer list) and it is not a
control statement (if, for, while, switch, catch). Lambdas and blocks inside
a function count towards that function.
"""
import argparse
import os
import re
import sys

CONTROL = re.compile(r"\b(if|for|while|switch|catch|do|else)\s*(\(.*\))?\s*$", re.S)
# Each qualifier with its own trailing spaces (no two ways to match a run of
# spaces: an alternation of qualifiers and single spaces under a star,
# between two runs of spaces, backtracked for minutes over a long blanked
# comment after a parenthesis).
SIGNATURE = re.compile(
    r"\)\s*(?:(?:const|override|final|noexcept|mutable)\b\s*)*(?:->\s*[\w:<>,&*][\w:<>,\s&*]*)?$", re.S)
INIT_LIST = re.compile(r"\)\s*:\s*[\w:]+\s*[({].*[)}]\s*$", re.S)


def strip_code(text):
    """Text with comments, string and char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = ")" + (m.group(1) if m else "") + '"'
            j = text.find(end, i)
            j = n if j < 0 else j + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (min(j, n) - i - 1) + (c if j < n else ""))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(name, first_line, last_line) of every top-level function body."""
    code = strip_code(text)
    result = []
    stack = []  # (kind, start_line, name)
    last_stmt_end = 0
    line = 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            head = code[last_stmt_end:i]
            in_function = any(k == "function" for k, _, _ in stack)
            kind = "block"
            name = ""
            if not in_function:
                h = head.strip()
                if (SIGNATURE.search(h) or INIT_LIST.search(h)) and not CONTROL.search(h) and "=" not in h.split("(")[0]:
                    kind = "function"
                    m = re.search(r"([~\w:]+)\s*\(", h)
                    name = m.group(1) if m else "?"
            stack.append((kind, line, name))
            last_stmt_end = i + 1
        elif c == "}":
            if stack:
                kind, start, name = stack.pop()
                if kind == "function":
                    result.append((name, start, line))
            last_stmt_end = i + 1
        elif c == ";":
            last_stmt_end = i + 1
    return result


def check(dirs, max_function):
    problems = []
    for d in dirs:
        for root, _, files in os.walk(d):
            for f in sorted(files):
                if not f.endswith((".h", ".cpp", ".hpp", ".cc")):
                    continue
                path = os.path.join(root, f)
                with open(path, encoding="utf-8", errors="replace") as fh:
                    text = fh.read()
                if f.endswith((".h", ".hpp")) and re.search(r"#include\s*<pcl/", text):
                    private_glue = f.startswith("pcl_") and "recognition" in os.path.normpath(path).split(os.sep)
                    if not private_glue:
                        problems.append("%s: a header includes PCL (only src/recognition/**/pcl_*.h may)" % path)
                for name, a, b in functions(text):
                    if b - a + 1 > max_function:
                        problems.append("%s:%d: function %s is %d lines (limit %d)" %
                                        (path, a, name, b - a + 1, max_function))
    return problems


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--max-function", type=int, default=80)
    ap.add_argument("dirs", nargs="*", default=["src"])
    a = ap.parse_args(argv)
    problems = check(a.dirs, a.max_function)
    for p in problems:
        print(p)
    if not problems:
        print("structure: every function <= %d lines" % a.max_function)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
