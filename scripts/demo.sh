#!/usr/bin/env bash
# Demo: set-up (packages, build), then the main job on built-in data: a small
# experiment (configs/experiments/demo.yaml: 4 generated table images of the
# LS5, CVFH / CESF / SHOT / FPFH with ICP), reported as the thesis's Table 4.1
# with the thesis's values beside ours. Only the project's own procedural
# models are needed. Re-running resumes: finished trials are not redone.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/setup.sh" --only posebench   # the tests and benchmarks: scripts/test.sh
cd "$ROOT"
JOBS="${POSEBENCH_JOBS:-$(nproc)}"
echo "demo: running configs/experiments/demo.yaml with $JOBS worker(s) (results/demo)"
build/posebench run configs/experiments/demo.yaml --out results/demo --jobs "$JOBS"
build/posebench report results/demo --format md,csv,tex --html
preview=$(ls -d scenes/table_synthetic_*/depth_preview.png 2>/dev/null | head -1 || true)
echo
echo "demo: records in results/demo/records.jsonl, tables in results/demo/report.{md,csv,tex},"
echo "      one page with tables and a failure gallery in results/demo/report.html (open it in a browser),"
echo "      BOP results CSVs in results/demo/bop/${preview:+, a depth preview in $preview}"
echo "      one image by hand: build/posebench recognize --dataset $(dirname "${preview:-scenes/x/y}") --scene 1 --image 0 --object ls5 --method fpfh --refine icp --overlay overlay.png"
