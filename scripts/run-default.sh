#!/usr/bin/env bash
# The main job on the built-in default scene: installs what is needed, builds,
# generates the procedural landscape, builds its LDC (out/default.ldc), prints
# `ldc info` for it, then digs a tunnel through it with a chamber and a pillar
# (scripts/default-tunnel.json): the landscape is contoured once, each edit
# re-meshes only what it changed, and the result is written as out/tunnel.ldc
# and the re-meshed out/tunnel.glb, with per-edit times and the quality report.
# Then `ldc path` finds a walking path (agent 2 m tall, 0.6 m radius) from the
# tunnel's east mouth through the tunnel into the dug chamber (out/path.json),
# and `ldc render` draws the dug landscape from the south-east as
# out/tunnel.png (one ray cast per pixel, with shadows) with that path on top:
# dashed where the ground hides it (docs/images/default-landscape.png is a copy).
# Last, examples/game_loop plays 60 frames on the landscape (each frame: a dig
# or a build, re-mesh, nav update, an agent re-planning, ground ray casts) and
# prints the per-frame timings as a table with median, p95 and max; four of
# its frames are rendered to out/game_loop/frame_*.png. Then examples/flythrough
# flies 5 s over a 4 km x 4 km landscape generated chunk by chunk under a
# memory budget, digging once a second and saving the digs to
# out/flythrough.ldcs, and prints its per-frame timings and peak memory
# (frames in out/flythrough/).
# Finally `ldc gi` lights the same view by cone tracing through the voxel cascades
# (Vulkan; lavapipe without a GPU) and writes out/tunnel-gi.png.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
./build/tools/ldc terrain -o out/default.ldc
./build/tools/ldc info out/default.ldc
./build/tools/ldc edit out/default.ldc --script scripts/default-tunnel.json -o out/tunnel.ldc \
  --validate --mesh out/tunnel.glb
./build/tools/ldc path out/tunnel.ldc --from 42,10.2,2 --to 24,7.5,2 -o out/path.json
./build/tools/ldc render out/tunnel.ldc -o out/tunnel.png --camera 61,-5,10 --target 45,11,3.4 --fov 55 \
  --width 960 --height 540 --shadows --overlay out/path.json
./build/examples/game_loop/game_loop --frames 60 --png out/game_loop
./build/examples/flythrough/flythrough --frames 300 --store out/flythrough.ldcs --png out/flythrough --quiet
./build/tools/ldc gi out/tunnel.ldc -o out/tunnel-gi.png --camera 61,-5,10 --target 45,11,3.4 --fov 55 \
  --width 480 --height 270
