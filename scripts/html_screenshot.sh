#!/usr/bin/env bash
# Renders a posebench HTML report in headless Chromium (Debian's chromium)
# and writes a screenshot:
#
#   scripts/html_screenshot.sh REPORT.html OUT.png [WIDTH,HEIGHT]
#
# Prints the page's own status line once loaded ("images loaded: K of N",
# written by its script) and exits 1 unless every image loaded, 2 when
# chromium is missing or the page does not exist.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: html_screenshot.sh REPORT.html OUT.png [WIDTH,HEIGHT]" >&2; exit 2; }
page="$(realpath "$1")" || exit 2
[ -f "$page" ] || { echo "html_screenshot.sh: no file $1" >&2; exit 2; }
command -v chromium >/dev/null || { echo "html_screenshot.sh: chromium not installed (apt install chromium)" >&2; exit 2; }
size="${3:-1280,1600}"
profile="$(mktemp -d)"  # a throw-away browser profile
trap 'rm -rf "$profile"' EXIT
flags=(--headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$profile")
status="$(chromium "${flags[@]}" --dump-dom "file://$page" 2>/dev/null | grep -o 'images loaded: [0-9]* of [0-9]*' || true)"
chromium "${flags[@]}" --window-size="$size" --screenshot="$2" "file://$page" >/dev/null 2>&1
[ -s "$2" ] || { echo "html_screenshot.sh: no screenshot written" >&2; exit 1; }
echo "${status:-images loaded: status line not found}"
read -r k n <<<"$(echo "$status" | grep -o '[0-9]*' | tr '\n' ' ')"
[ -n "${k:-}" ] && [ "$k" = "$n" ]
