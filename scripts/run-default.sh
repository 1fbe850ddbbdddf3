#!/usr/bin/env bash
# The main job on the built-in default scene: installs what is needed, builds,
# generates the procedural landscape, builds its LDC, writes out/default.ldc,
# prints `ldc info` for it, and contours it into out/default.glb with the
# mesh quality report.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
./build/tools/ldc terrain -o out/default.ldc
./build/tools/ldc info out/default.ldc
./build/tools/ldc contour out/default.ldc -o out/default.glb
