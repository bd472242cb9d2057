#!/usr/bin/env bash
# Regenerates the thesis's tables and figures (its chapter 4) and writes
# results/thesis/README.md beside the thesis's numbers.
#
#   scripts/thesis.sh [--jobs N] [--only NAME[,NAME...]] [--ablations] [--readme-only]
#
# Runs every experiment of configs/thesis/ (table_4_1 ... fig_4_12) with
# `posebench run` into results/thesis/raw/NAME (git-ignored; the run itself
# logs its wall time and load to NAME/runs.jsonl), reports each (markdown,
# csv, plots), copies the plots to results/thesis/plots/ and writes
# results/thesis/README.md and cells.csv with scripts/thesis_report.py (with
# the ablation pairs of configs/thesis/ablations.yaml whose folders exist).
# Resumable: `posebench run` only runs the trials a results folder is missing,
# so running this again after an interruption (or after adding an experiment)
# does only what is missing. --ablations: also the ablation experiments of
# configs/thesis/ablations.yaml (each cause of a gap switched back; their
# configs are derived into results/thesis/raw/configs/ by
# scripts/thesis_ablations.py; --only may name them). --readme-only: report
# and rewrite the README from the raw folders (none yet: the README is left
# as it is).
#
# Environment: POSEBENCH (the binary, default build/posebench), JOBS (worker
# processes, default 2), NICE (niceness of the runs, default 0). Workers run
# single-threaded (OMP_NUM_THREADS=1) so that N jobs use N cores.
set -euo pipefail
cd "$(dirname "$0")/.."

PB=${POSEBENCH:-build/posebench}
JOBS=${JOBS:-2}
NICE=${NICE:-0}
ONLY=""
README_ONLY=0
ABLATIONS=0
while [ $# -gt 0 ]; do
  case "$1" in
    --jobs) JOBS=$2; shift 2 ;;
    --only) ONLY=$2; shift 2 ;;
    --readme-only) README_ONLY=1; shift ;;
    --ablations) ABLATIONS=1; shift ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    *) echo "thesis.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
OUT=results/thesis
RAW=$OUT/raw
EXPERIMENTS=(table_4_1 table_4_3 table_4_4 table_4_5 table_4_7 table_4_9 fig_4_6 fig_4_12
             fig_4_7_global fig_4_7_local fig_4_11_global fig_4_11_local)

# --readme-only with no raw results (a fresh clone) has nothing to report:
# no binary needed, and thesis_report.py leaves the committed README alone.
have_results() {
  local e
  for e in "${EXPERIMENTS[@]}"; do [ -f "$RAW/$e/records.jsonl" ] && return 0; done
  return 1
}
if [ ! -x "$PB" ] && { [ "$README_ONLY" = 0 ] || have_results; }; then
  echo "thesis.sh: no posebench binary at '$PB' (build it: cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build --target posebench, or set POSEBENCH)" >&2
  exit 2
fi
mkdir -p "$OUT/plots"
[ "$README_ONLY" = 1 ] || mkdir -p "$RAW"

selected() {
  [ -z "$ONLY" ] && return 0
  case ",$ONLY," in *",$1,"*) return 0 ;; esac
  return 1
}

run_one() {  # NAME CONFIG
  echo "== $1: $(date '+%F %T')" >&2
  OMP_NUM_THREADS=1 nice -n "$NICE" "$PB" run "$2" --out "$RAW/$1" --jobs "$JOBS" \
    --cache cache --scenes scenes > "$RAW/$1.run.txt" 2> "$RAW/$1.progress.txt" ||
    { echo "thesis.sh: $1 failed:" >&2; tail -5 "$RAW/$1.progress.txt" >&2; exit 1; }
  cat "$RAW/$1.run.txt" >&2
}

if [ "$README_ONLY" = 0 ]; then
  for e in "${EXPERIMENTS[@]}"; do
    if selected "$e"; then run_one "$e" "configs/thesis/$e.yaml"; fi
  done
  if [ "$ABLATIONS" = 1 ]; then
    /usr/bin/python3 scripts/thesis_ablations.py configs/thesis/ablations.yaml "$RAW/configs" > "$RAW/configs.txt" ||
      exit 2
    while read -r name path; do
      if selected "$name"; then run_one "$name" "$path"; fi
    done < "$RAW/configs.txt"
  fi
fi

REPORTED=("${EXPERIMENTS[@]}")
for d in "$RAW"/ablation_*/; do
  [ -d "$d" ] && REPORTED+=("$(basename "$d")")
done
for e in "${REPORTED[@]}"; do
  [ -f "$RAW/$e/records.jsonl" ] || continue
  "$PB" report "$RAW/$e" --format md,csv --plots > /dev/null 2> "$RAW/$e/report.log" ||
    { echo "thesis.sh: report of $e failed:" >&2; cat "$RAW/$e/report.log" >&2; exit 1; }
  case "$e" in ablation_*) continue ;; esac  # the README compares their cells; no plots of their own
  for p in "$RAW/$e"/plots/*.png; do
    [ -f "$p" ] && cp "$p" "$OUT/plots/${e}_$(basename "$p")"
  done
done

# The README: every number from the raw folders (records checked against
# `posebench schema record`, reports, runs.jsonl); exit 2 on a bad record.
POSEBENCH="$PB" JOBS=$JOBS /usr/bin/python3 scripts/thesis_report.py "$OUT" "${EXPERIMENTS[@]}"
