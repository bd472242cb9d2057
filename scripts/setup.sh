#!/usr/bin/env bash
# Idempotent set-up: installs the Debian packages that are missing, then
# configures and builds posebench (Release) into build/.
#   scripts/setup.sh                  everything: the tool, tests, benchmarks
#   scripts/setup.sh --only posebench the tool alone (what the demo runs)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
TARGET_ARGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --only) [ $# -ge 2 ] || { echo "setup.sh: --only needs a target name" >&2; exit 2; }
            TARGET_ARGS=(--target "$2"); shift 2 ;;
    *) echo "setup.sh: unknown argument '$1' (--only TARGET)" >&2; exit 2 ;;
  esac
done

PACKAGES=(build-essential cmake pkg-config ccache libpcl-dev libeigen3-dev libosmesa6-dev
          libassimp-dev nlohmann-json3-dev libyaml-cpp-dev libbenchmark-dev libgtest-dev
          libpng-dev libdeflate-dev libcli11-dev libspdlog-dev python3 python3-matplotlib python3-yaml python3-numpy
          slurm-wlm munge  # a one-node Slurm for the sweep scripts' test (scripts/slurm)
          chromium)        # headless, for the HTML report's rendering test (scripts/html_screenshot.sh)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

export CCACHE_BASEDIR="$ROOT"
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
# A PCL-heavy translation unit takes about 2 GB and a minute: at most one
# job per core.
JOBS="${POSEBENCH_BUILD_JOBS:-$(nproc)}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${POSEBENCH_CMAKE_ARGS:-} >/dev/null
cmake --build build -j "$JOBS" ${TARGET_ARGS[@]+"${TARGET_ARGS[@]}"}

# The project's own models, generated in code, written as meshes (mm) for
# viewers and other tools; the registry lists every model and its state.
build/posebench models --write models/generated >/dev/null
