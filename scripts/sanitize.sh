#!/usr/bin/env bash
# Builds posebench and its tests with AddressSanitizer + UndefinedBehavior-
# Sanitizer (gcc, -fsanitize=address,undefined) in build-asan/ and runs
# ctest there. Any report fails the test that produced it.
#
#   scripts/sanitize.sh            # everything (docs/testing.md, "Sanitizers", has the time)
#   scripts/sanitize.sh --reduced  # the unit tests of io, eval and runner (.ci/run runs it)
#   scripts/sanitize.sh -- -R Bop  # extra ctest arguments after --
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
REDUCED=0
CTEST_ARGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --reduced) REDUCED=1; shift ;;
    --) shift; CTEST_ARGS+=("$@"); break ;;
    *) echo "sanitize.sh: unknown argument '$1' (--reduced, -- CTEST ARGS)" >&2; exit 2 ;;
  esac
done
"$ROOT/scripts/setup.sh"  # packages, and the Release build the tests' data comes from
export CCACHE_BASEDIR="$ROOT" CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
JOBS="${POSEBENCH_BUILD_JOBS:-$(nproc)}"
# Leaks inside uninstrumented libraries (Mesa, VTK, OpenMP) are theirs, not
# ours: tests/sanitize/lsan.supp lists them.
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$ROOT/tests/sanitize/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
if [ "$REDUCED" -eq 1 ]; then
  # The unit tests of io, eval and runner, with every library instrumented
  # but recognition and io_pcl (PCL-heavy; compiled as in the Release build,
  # so ccache has them): minutes, not the full build's half hour.
  DIR=build-asan-reduced
  cmake -S . -B "$DIR" -DCMAKE_BUILD_TYPE=Release -DPOSEBENCH_SANITIZE=ON \
    "-DPOSEBENCH_SANITIZE_SKIP=recognition;io_pcl" -DPOSEBENCH_BUILD_BENCH=OFF >/dev/null
  TARGETS=(posebench)
  for t in tests/test_io_*.cpp tests/test_eval_*.cpp tests/test_runner_*.cpp; do TARGETS+=("$(basename "${t%.cpp}")"); done
  # The fuzz findings' replays (FuzzRegressions.NAME, labelled io or runner).
  for d in fuzz/regressions/*/; do
    n="$(basename "$d")"
    case "$n" in fuzz_scene_yaml|fuzz_models_yaml|fuzz_training_cache) ;; *) TARGETS+=("replay_$n") ;; esac
  done
  cmake --build "$DIR" -j "$JOBS" --target "${TARGETS[@]}"
  ctest --test-dir "$DIR" --output-on-failure -j "$(nproc)" -L '^(io|eval|runner)$' "${CTEST_ARGS[@]}"
else
  DIR=build-asan
  cmake -S . -B "$DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOSEBENCH_SANITIZE=ON -DPOSEBENCH_SANITIZE_SKIP= \
    -DPOSEBENCH_BUILD_BENCH=OFF >/dev/null
  cmake --build "$DIR" -j "$JOBS"
  ctest --test-dir "$DIR" --output-on-failure -j "$(nproc)" "${CTEST_ARGS[@]}"
fi
