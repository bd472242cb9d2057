#!/usr/bin/env bash
# Submits a posebench sweep to Slurm: a job array of N shards
# (scripts/slurm/sweep.sbatch) and a merge job that waits for all of them
# (scripts/slurm/merge.sbatch, --dependency=afterany).
#
#   scripts/slurm/submit.sh EXPERIMENT.yaml N [OUT] [-- RUN OPTIONS...] [--sbatch "SBATCH OPTIONS"]
#
# OUT defaults to results/<experiment file stem>. RUN OPTIONS go to every
# `posebench run` (e.g. --cache /shared/cache --scenes /shared/scenes).
# SBATCH OPTIONS go to both sbatch calls (e.g. "--partition=cpu --time=4:00:00").
# Prints the two job ids ("array JOBID", "merge JOBID"); Slurm writes the
# tasks' output to OUT/slurm/. Run from anywhere: jobs run in the project root.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
usage() { echo "usage: submit.sh EXPERIMENT.yaml N [OUT] [-- RUN OPTIONS...] [--sbatch \"OPTIONS\"]" >&2; exit 2; }
[ $# -ge 2 ] || usage
EXPERIMENT="$1"
N="$2"
shift 2
[[ "$N" =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: N must be a positive integer (is '$N')" >&2; exit 2; }
OUT="results/$(basename "${EXPERIMENT%.*}")"
if [ $# -gt 0 ] && [ "$1" != "--" ] && [ "$1" != "--sbatch" ]; then OUT="$1"; shift; fi
SBATCH_OPTS=()
RUN_OPTS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --sbatch) [ $# -ge 2 ] || usage; read -r -a SBATCH_OPTS <<<"$2"; shift 2 ;;
    --) shift; while [ $# -gt 0 ] && [ "$1" != "--sbatch" ]; do RUN_OPTS+=("$1"); shift; done ;;
    *) usage ;;
  esac
done
cd "$ROOT"
[ -f "$EXPERIMENT" ] || { echo "submit.sh: $EXPERIMENT: no such experiment file (paths are relative to $ROOT)" >&2; exit 2; }
POSEBENCH="${POSEBENCH:-$ROOT/build/posebench}"
[ -x "$POSEBENCH" ] || { echo "submit.sh: $POSEBENCH: not built (scripts/setup.sh)" >&2; exit 2; }
mkdir -p "$OUT/slurm"
array=$(sbatch --parsable --array="0-$((N - 1))" --chdir="$ROOT" --output="$OUT/slurm/shard_%a.out" \
  --export=ALL,POSEBENCH="$POSEBENCH" "${SBATCH_OPTS[@]}" \
  scripts/slurm/sweep.sbatch "$EXPERIMENT" "$OUT" "${RUN_OPTS[@]}")
array="${array%%;*}"  # --parsable prints JOBID[;CLUSTER]
merge=$(sbatch --parsable --dependency="afterany:$array" --chdir="$ROOT" --output="$OUT/slurm/merge.out" \
  --export=ALL,POSEBENCH="$POSEBENCH" "${SBATCH_OPTS[@]}" scripts/slurm/merge.sbatch "$OUT")
merge="${merge%%;*}"
echo "array $array"
echo "merge $merge"
