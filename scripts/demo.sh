#!/usr/bin/env bash
# Demo: set-up (packages, build), then the main job on built-in data: a small
# table scene set (5 images of configs/scenes/table_synthetic.yaml, the
# project's own procedural models only) written to scenes/demo in the BOP
# layout, with a colour-mapped depth preview of the first image and a
# summary (images, objects, the target's mean visible fraction).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/setup.sh"
cd "$ROOT"
CONFIG="${POSEBENCH_DEMO_CONFIG:-configs/scenes/table_synthetic.yaml}"
IMAGES="${POSEBENCH_DEMO_IMAGES:-5}"
echo "demo: generating $IMAGES images of $CONFIG into scenes/demo"
build/posebench generate "$CONFIG" --out scenes/demo --images "$IMAGES" --quiet
echo "demo: per image (camera distance, elevation, objects, target visible fraction):"
python3 - scenes/demo/posebench_scene.json <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for im in d["images"]:
    print("  image %d: camera %.0f mm at %.0f deg, %d objects%s, target visib_fract %.2f" % (
        im["im_id"], im["camera_distance_mm"], im["camera_elevation_deg"], len(im["objects"]),
        " (occluded)" if im["occluded"] else "", im["target_visib_fract"]))
PY
echo "demo: done; BOP data set in scenes/demo, preview scenes/demo/depth_preview.png"
