#!/usr/bin/env bash
# Set-up (packages, build), then every test through ctest.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/setup.sh"
cd "$ROOT"
ctest --test-dir build --output-on-failure -j "$(nproc)" "$@"
