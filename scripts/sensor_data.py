#!/usr/bin/env python3
"""Writes the real depth frames listed in results/sensors/sources.json from
local git snapshots of their repositories (never committed here):

    python3 scripts/sensor_data.py --mirrors DIR --out DATA [--sources FILE]
        [--kind structured_light|time_of_flight]

DIR holds one bare git directory per repository, DIR/OWNER+NAME/repo (the
layout the project's snapshot tool writes); each frame is `git show
COMMIT:PATH` into DATA/LOCAL, and its origin is printed."""
import argparse
import json
import os
import subprocess

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mirrors", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--sources", default=os.path.join(ROOT, "results", "sensors", "sources.json"))
    ap.add_argument("--kind", help="only the frames of this kind (a sensor's fit needs only its own)")
    args = ap.parse_args(argv)
    with open(args.sources) as f:
        frames = json.load(f)["frames"]
    for fr in frames:
        if args.kind and fr["kind"] != args.kind:
            continue
        git_dir = os.path.join(args.mirrors, fr["repo"].replace("/", "+"), "repo")
        dest = os.path.join(args.out, fr["local"])
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        with open(dest, "wb") as out:
            subprocess.run(["git", "--git-dir", git_dir, "show", "%s:%s" % (fr["commit"], fr["path"])],
                           stdout=out, check=True)
        print("%s <- %s %s @ %s" % (dest, fr["repo"], fr["path"], fr["commit"]))


if __name__ == "__main__":
    main()
