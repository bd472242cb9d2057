"""Wall times and loads of an experiment's `posebench run` invocations:
runs.jsonl, or the run_seconds.txt of older folders."""
import json
import os

from .schema import InputError


class Runs:
    """What a folder says of its `posebench run` invocations that ran trials:
    wall seconds, 15-minute loads at their ends, trials ran; `source` is the
    file read (runs.jsonl, or run_seconds.txt of older runs), None without."""

    def __init__(self, seconds=0.0, loads=(), ran=0, source=None):
        self.seconds, self.loads, self.ran, self.source = seconds, list(loads), ran, source

    @property
    def known(self):
        return self.source is not None

    def add(self, wall, ran, load):
        self.seconds += wall
        self.ran += ran
        if load is not None:
            self.loads.append(load)


def load_runs(path):
    """Wall seconds (sum of wall_s), 15-minute loads at the end (load15_end)
    and trials ran (sum of ran), over the lines of a runs.jsonl with "ran" > 0."""
    if not os.path.exists(path):
        return Runs()
    runs = Runs(source="runs.jsonl")
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if not line.strip():
                continue
            try:
                r = json.loads(line)
                ran, wall = int(r["ran"]), float(r["wall_s"])
                load = None if r.get("load15_end") is None else float(r["load15_end"])
            except (ValueError, TypeError, KeyError, AttributeError) as e:
                raise InputError("%s: line %d: not a run summary (%s: %s)" % (path, n, type(e).__name__, e))
            if ran > 0:
                runs.add(wall, ran, load)
    return runs


def load_run_seconds(path):
    """The same from the run_seconds.txt that scripts/thesis.sh kept before
    runs.jsonl existed: one line per invocation that ran trials,
    `DATE TIME WALL_SECONDS RAN JOBS LOAD15`."""
    if not os.path.exists(path):
        return Runs()
    runs = Runs(source="run_seconds.txt")
    with open(path) as f:
        for n, line in enumerate(f, 1):
            fields = line.split()
            if not fields:
                continue
            try:
                runs.add(float(fields[2]), int(fields[3]), float(fields[5]) if len(fields) > 5 else None)
            except (ValueError, IndexError) as e:
                raise InputError("%s: line %d: not `DATE TIME WALL_SECONDS RAN JOBS LOAD15` (%s)" % (path, n, e))
    return runs


def load_folder_runs(d):
    """runs.jsonl of a results folder, else its older run_seconds.txt."""
    runs = load_runs(os.path.join(d, "runs.jsonl"))
    return runs if runs.known else load_run_seconds(os.path.join(d, "run_seconds.txt"))
