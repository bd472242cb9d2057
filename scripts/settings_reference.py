#!/usr/bin/env python3
"""Writes docs/settings.md, the reference of every recognition setting.

    scripts/settings_reference.py [--posebench BIN | --schema FILE] [--src DIR] [--out FILE | --check FILE]

The keys, types, defaults and accepted values come from the binary
(`posebench schema settings`, which walks each settings struct's fields()
list); what each setting does comes from the comment beside (or above) its
member in the struct's header under --src (default src). A struct is found
by its fields() list: the one whose keys are the section's keys. So the
reference cannot drift from the code: --check FILE exits 1 when FILE differs
from what would be written (a ctest runs it). Exit 2 for unreadable input.
"""
import argparse
import json
import os
import re
import subprocess
import sys

FIELD_CALL = re.compile(r'\bf\("(\w+)",\s*s\.(\w+)')
MEMBER = re.compile(r"^\s*(?:[\w:<>,]+\s+)+?(\w+)(?:\s*=\s*[^;]*)?;\s*(?://\s?(.*))?$")
COMMENT = re.compile(r"^(\s*)//\s?(.*)$")


def struct_docs(text):
    """{frozenset of fields() keys: {key: doc}} for each struct with a fields() list."""
    out = {}
    lines = text.split("\n")
    for m in re.finditer(r"\bstruct\s+\w+\s*(?::[^{;]*)?{", text):
        start = text.count("\n", 0, m.start())
        depth, end = 0, None
        for i in range(start, len(lines)):
            depth += lines[i].count("{") - lines[i].count("}")
            if depth == 0 and i > start:
                end = i
                break
        if end is None:
            continue
        body = lines[start + 1:end]
        calls = [(k, mem) for line in body for k, mem in FIELD_CALL.findall(line)]
        if not calls:
            continue
        docs = member_docs(body)
        out[frozenset(k for k, _ in calls)] = {k: docs.get(mem, "") for k, mem in calls}
    return out


def member_docs(body):
    """{member: its comment}: the comment on its line and the comment lines
    indented to that comment's column below it, else the comment block right
    above it."""
    docs = {}
    i = 0
    while i < len(body):
        line = body[i]
        m = MEMBER.match(line) if "(" not in line.split("//")[0] else None
        if not m:
            i += 1
            continue
        name, text = m.group(1), [m.group(2)] if m.group(2) else []
        if text:
            col = line.index("//")
            j = i + 1
            while j < len(body):
                c = COMMENT.match(body[j])
                if not c or len(c.group(1)) < col:
                    break
                text.append(c.group(2))
                j += 1
        else:  # the block above, at the member's own indentation
            indent = len(line) - len(line.lstrip())
            j = i - 1
            while j >= 0 and COMMENT.match(body[j]) and len(COMMENT.match(body[j]).group(1)) == indent:
                text.insert(0, COMMENT.match(body[j]).group(2))
                j -= 1
        docs[name] = " ".join(t.strip() for t in text if t.strip())
        i += 1
    return docs


def collect_docs(src):
    docs = {}
    for root, _, files in os.walk(src):
        for f in sorted(files):
            if f.endswith(".h"):
                with open(os.path.join(root, f), encoding="utf-8") as fh:
                    docs.update(struct_docs(fh.read()))
    return docs


def section_docs(keys, docs):
    """The docs of the struct whose fields() keys are the section's, else
    those of the structs whose keys together make it up (a struct with a
    base, as RefineSettings lists RegistrationSettings' fields first)."""
    if keys in docs:
        return docs[keys]
    out = {}
    for struct_keys, d in docs.items():
        if struct_keys <= keys:
            out.update(d)
    return out


def fmt(v):
    return json.dumps(v) if not isinstance(v, str) else v


def render(schema, docs):
    out = ["# Recognition settings", "",
           "Every setting of the recognition pipeline: its YAML section and key, its",
           "default, what it accepts and what it does. Written by",
           "`scripts/settings_reference.py` from `posebench schema settings` and the",
           "settings structs' comments; a test fails when this page and the code differ.",
           "Give them in a recognition config (`recognize --config`) or an experiment's",
           "`settings:` block; lengths may be fractions of the object's diameter (`0.05d`).",
           ""]
    out += ["## Top level", ""]
    for key in ("descriptor", "refinement", "seed"):
        e = schema[key]
        out.append(f"- `{key}`: {e['type']}, default `{fmt(e['default'])}`; {e['accepts']}")
    out.append("")
    for sec in schema["sections"]:
        doc = section_docs(frozenset(f["key"] for f in sec["fields"]), docs)
        out += [f"## {sec['name']}", ""]
        for f in sec["fields"]:
            accepts = f"; {f['accepts']}" if f["accepts"] else ""
            what = doc.get(f["key"], "")
            out.append(f"- `{f['key']}`: {f['type']}, default `{fmt(f['default'])}`{accepts}."
                       + (f" {what}" if what else ""))
        out.append("")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--posebench", default="build/posebench")
    g.add_argument("--schema")
    ap.add_argument("--src", default="src")
    o = ap.add_mutually_exclusive_group()
    o.add_argument("--out", default="docs/settings.md")
    o.add_argument("--check")
    a = ap.parse_args(argv)
    try:
        if a.schema:
            with open(a.schema, encoding="utf-8") as fh:
                schema = json.load(fh)
        else:
            schema = json.loads(subprocess.run([a.posebench, "schema", "settings"], check=True,
                                               capture_output=True, text=True).stdout)
        schema["sections"]
    except (OSError, ValueError, KeyError, subprocess.CalledProcessError) as e:
        print(f"settings_reference.py: cannot read the settings schema: {e}", file=sys.stderr)
        return 2
    text = render(schema, collect_docs(a.src))
    if a.check:
        try:
            with open(a.check, encoding="utf-8") as fh:
                current = fh.read()
        except OSError as e:
            print(f"settings_reference.py: {a.check}: {e}", file=sys.stderr)
            return 2
        if current != text:
            print(f"settings_reference.py: {a.check} is out of date: run scripts/settings_reference.py",
                  file=sys.stderr)
            return 1
        return 0
    with open(a.out, "w", encoding="utf-8") as fh:
        fh.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
