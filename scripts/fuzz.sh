#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/fuzz_*.cpp: every loader of user files)
# with clang, ASan and UBSan in build-fuzz/, seeds each corpus from the
# project's own files, and runs every target.
#
#   scripts/fuzz.sh [--seconds N | --runs N] [--only NAME] [--light]
#
# --seconds N: each target runs N seconds (default 60); --runs N: each runs N
# inputs instead (e.g. --runs 1000000). --light: only the targets that need
# no PCL (all but experiment YAML and the training cache), which build in
# minutes (a smoke run: `--light --seconds 4`). A crash, a sanitizer report, a
# time-out (> 10 s on one input) or an exception other than InputError stops
# that target: the input is saved as build-fuzz/findings/NAME/crash-*, the
# script goes on with the others and exits 1 at the end. Findings fixed are
# kept as regression inputs in fuzz/regressions/NAME/, which every run
# replays first. Prints one line per target: executions, seconds, result.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
SECONDS_EACH=60
RUNS=""
ONLY=""
LIGHT=0
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) SECONDS_EACH="$2"; shift 2 ;;
    --runs) RUNS="$2"; shift 2 ;;
    --only) ONLY="$2"; shift 2 ;;
    --light) LIGHT=1; shift ;;
    *) echo "fuzz.sh: unknown argument '$1' (--seconds N, --runs N, --only NAME)" >&2; exit 2 ;;
  esac
done
"$ROOT/scripts/setup.sh" >/dev/null  # packages and the Release build (it writes the seed scenes and cache)
for p in clang libfuzzer-14-dev libomp-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || MISSING="${MISSING:-} $p"
done
if [ -n "${MISSING:-}" ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $MISSING
fi
export CCACHE_BASEDIR="$ROOT" CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOSEBENCH_FUZZ=ON \
  -DPOSEBENCH_BUILD_TESTS=OFF -DPOSEBENCH_BUILD_BENCH=OFF >/dev/null
TARGETS=()
for f in fuzz/fuzz_*.cpp; do
  n="$(basename "${f%.cpp}")"
  if [ "$LIGHT" -eq 1 ] && { [ "$n" = fuzz_experiment_yaml ] || [ "$n" = fuzz_training_cache ]; }; then continue; fi
  if [ -z "$ONLY" ] || [ "$n" = "$ONLY" ] || [ "$n" = "fuzz_$ONLY" ]; then TARGETS+=("$n"); fi
done
[ ${#TARGETS[@]} -gt 0 ] || { echo "fuzz.sh: no target '$ONLY' in fuzz/" >&2; exit 2; }
cmake --build build-fuzz -j "${POSEBENCH_BUILD_JOBS:-$(nproc)}" --target "${TARGETS[@]}"

# Seeds: the project's own files (a scene set and a training cache come from
# the Release build; they are made once in build-fuzz/seeds).
SEEDS=build-fuzz/seeds
if [ ! -d "$SEEDS/ds" ]; then
  build/posebench generate configs/scenes/table_synthetic.yaml --images 2 --out "$SEEDS/ds" >/dev/null
  build/posebench run configs/experiments/demo.yaml -q --out "$SEEDS/run" --scenes "$SEEDS/scenes" \
    --cache "$SEEDS/cache" >/dev/null
fi
seed() {  # seed NAME FILE [PREFIX_BYTE]
  local dir="build-fuzz/corpus/$1"
  mkdir -p "$dir"
  local out="$dir/seed_$(basename "$2")${3:+_$3}"
  if [ -n "${3:-}" ]; then { printf "\\x$(printf %02x "$3")"; cat "$2"; } >"$out"; else cp "$2" "$out"; fi
}
scene="$SEEDS/ds/test/000001"
for f in configs/experiments/*.yaml configs/experiments/scale/*.yaml configs/thesis/*.yaml fuzz/seeds/experiment_relative.yaml fuzz/seeds/experiment_all.yaml; do
  seed fuzz_experiment_yaml "$f"
done
for f in configs/scenes/*.yaml; do seed fuzz_scene_yaml "$f"; done
seed fuzz_models_yaml models/models.yaml
seed fuzz_bop_camera "$SEEDS/ds/camera.json"
seed fuzz_bop_models_info "$SEEDS/ds/models/models_info.json"
seed fuzz_bop_test_targets fuzz/seeds/test_targets_bop19.json
seed fuzz_bop_results_csv fuzz/seeds/results_bop19.csv 1
seed fuzz_bop_scene "$scene/scene_camera.json" 0
seed fuzz_bop_scene "$scene/scene_gt.json" 1
seed fuzz_bop_scene "$scene/scene_gt_info.json" 2
# A 24x18 crop of a generated depth image: the decoder's paths are those of a
# full frame, at thousands rather than tens of inputs per second.
seed fuzz_png16 fuzz/seeds/depth_24x18.png
# The writer: a small mask (run encoder) and a small depth image (libdeflate).
seed fuzz_png_write fuzz/seeds/png_write_mask.bin
seed fuzz_png_write fuzz/seeds/png_write_depth.bin
for f in models/generated/box_small.ply models/generated/cylinder.ply; do seed fuzz_mesh "$f" 0; done
# Point clouds: the first byte's low bit picks .ply (1) or .pcd (0).
for f in fuzz/seeds/cloud_*.pcd; do seed fuzz_cloud "$f" 0; done
seed fuzz_cloud fuzz/seeds/cloud_60.ply 1
# The first byte picks the descriptor: its index in descriptor_names()
# (recognition/registry.cpp, alphabetical).
for f in "$SEEDS"/cache/*.bin; do
  d="$(basename "$f" | cut -d- -f2)"
  case "$d" in cesf) i=0 ;; cvfh) i=1 ;; esf) i=2 ;; fpfh) i=3 ;; ourcvfh) i=4 ;; ppf) i=5 ;; shot) i=6 ;; *) continue ;; esac
  seed fuzz_training_cache "$f" "$i"
done
for f in tests/data/expected_records/*.jsonl fuzz/seeds/records_instances.jsonl; do seed fuzz_records_jsonl "$f"; done

export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$ROOT/tests/sanitize/lsan.supp:print_suppressions=0"
failed=0
printf "%-24s %12s %8s  %s\n" target executions seconds result
for t in "${TARGETS[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/findings/$t" "fuzz/regressions/$t"
  log="build-fuzz/findings/$t/log.txt"
  limit=(-max_total_time="$SECONDS_EACH")
  [ -n "$RUNS" ] && limit=(-runs="$RUNS")
  # Regression inputs first (each must pass), then fuzzing.
  if ls "fuzz/regressions/$t"/* >/dev/null 2>&1 &&
     ! "build-fuzz/fuzz/$t" "fuzz/regressions/$t"/* >"build-fuzz/findings/$t/regressions.txt" 2>&1; then
    printf "%-24s %12s %8s  %s\n" "$t" - - "REGRESSION (build-fuzz/findings/$t/regressions.txt)"
    failed=1
    continue
  fi
  start=$(date +%s)
  if "build-fuzz/fuzz/$t" "${limit[@]}" -timeout=10 -rss_limit_mb=4096 -print_final_stats=1 \
       -artifact_prefix="build-fuzz/findings/$t/" "build-fuzz/corpus/$t" >"$log" 2>&1; then
    result=ok
  else
    result="FAILED (see $log)"
    failed=1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  printf "%-24s %12s %8s  %s\n" "$t" "${runs:-?}" "$(($(date +%s) - start))" "$result"
done
exit "$failed"
