"""The trial record's schema and the strict reader of records.jsonl.

Every record is checked against `posebench schema record` of the binary
(POSEBENCH) or, without one, against its copy in record_schema.json: an unknown
key or a missing required key is an InputError naming the file, the line and
the key.
"""
import difflib
import json
import os
import subprocess

# `posebench schema record` as the binary prints it (src/eval/record.cpp is
# the one definition), written to record_schema.json beside this file for
# when no binary is at hand:
#   build/posebench schema record > scripts/thesis_report/record_schema.json
# tests/scripts compare the file with the binary's schema.
SCHEMA_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "record_schema.json")
with open(SCHEMA_FILE) as _f:
    RECORD_SCHEMA = {"type": "object", "fields": json.load(_f)["fields"]}


PY_TYPES = {"string": (str,), "integer": (int,), "number": (int, float), "boolean": (bool,), "array": (list,),
            "object": (dict,)}


class InputError(Exception):
    """A results file that cannot be read as it should: names file, line and key."""


class KeyProblem(Exception):
    """A record's key (dotted path) that does not fit the schema: `what 'key'detail`."""

    def __init__(self, key, what, detail=""):
        super().__init__(key, what, detail)
        self.key, self.what, self.detail = key, what, detail

    def __str__(self):
        return "%s '%s'%s" % (self.what, self.key, self.detail)


def schema_from_binary(binary):
    """The schema `BINARY schema record` prints, or None without a binary."""
    if not binary or not os.access(binary, os.X_OK):
        return None
    try:
        r = subprocess.run([binary, "schema", "record"], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    try:
        return {"type": "object", "fields": json.loads(r.stdout)["fields"]} if r.returncode == 0 else None
    except (ValueError, KeyError, TypeError):
        return None


def is_required(flag, record):
    """Whether a key is required in `record`, by its schema's "required"."""
    if flag in ("when_ok", "when_gt"):
        return record.get("status") == "ok" and (flag == "when_ok" or "gt" in record)
    return flag is True


WHEN = {"when_ok": " (required with status ok)", "when_gt": " (required with status ok and gt)"}


def check_value(value, spec, record, path):
    """Raises KeyProblem(key path, what) where `value` does not fit `spec`."""
    ok = isinstance(value, PY_TYPES.get(spec.get("type"), (object,))) and not (isinstance(value, bool) and spec["type"] in
                                                           ("integer", "number"))
    if not ok:
        raise KeyProblem(path, "wrong type for key", " (%s, expected %s)" % (type(value).__name__, spec["type"]))
    if "values" in spec:
        for k, v in value.items():
            check_value(v, spec["values"], record, path + "." + k)
    elif "items" in spec:
        for i, v in enumerate(value):
            check_value(v, spec["items"], record, "%s[%d]" % (path, i))
    elif "fields" in spec:
        check_fields(value, spec["fields"], record, path)


def check_fields(obj, fields, record, path=""):
    prefix = path + "." if path else ""
    for k in obj:  # unknown keys first: a misspelt key is named as such
        if k not in fields:
            close = difflib.get_close_matches(k, list(fields), n=1)
            raise KeyProblem(prefix + k, "unknown key", " (did you mean '%s'?)" % close[0] if close else "")
    for k, spec in fields.items():
        if k in obj:
            check_value(obj[k], spec, record, prefix + k)
        elif is_required(spec.get("required"), record):
            raise KeyProblem(prefix + k, "missing required key", WHEN.get(spec.get("required"), ""))


def parse_record(line, schema, path, n):
    """Line n of a records.jsonl as a record that fits the schema."""
    try:
        r = json.loads(line)
    except ValueError as e:
        raise InputError("%s: line %d: not JSON (%s)" % (path, n, e)) from None
    if not isinstance(r, dict):
        raise InputError("%s: line %d: not a JSON object" % (path, n))
    try:
        check_fields(r, schema["fields"], r)
    except KeyProblem as p:
        raise InputError("%s: line %d: %s" % (path, n, p)) from None
    return r


def load_records(path, schema):
    """Every record of a records.jsonl, each checked against the schema."""
    with open(path) as f:
        return [parse_record(line, schema, path, n) for n, line in enumerate(f, 1) if line.strip()]
