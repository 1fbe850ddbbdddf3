#!/usr/bin/env bash
# Builds the benchmarks and writes their tables to docs/benchmarks.md.
# Run on an otherwise idle machine: the tables are wall-clock timings.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DLDC_BUILD_BENCH=ON
mkdir -p docs
{
  echo "# Benchmarks"
  echo
  echo "Written by \`scripts/bench.sh\`; every table compares ldc with a peer library measured in the same run."
  echo
  echo "## LDC build (issue 2)"
  echo
  ./build/bench/bench_build
  echo
  echo "## Dual contouring: remesh time against error (issue 3)"
  echo
  echo "Plots of time against error: contour_fandisk.svg, contour_rocker-arm.svg, contour_spot.svg,"
  echo "contour_stanford-bunny-filled.svg (in docs/)."
  echo
  ./build/bench/bench_contour --plots docs
  echo
  echo "## Mesh booleans against CGAL corefinement and OpenVDB (issue 4)"
  echo
  echo "Plots of time against error: csg_bunny_sphere.svg, csg_bunny_sphere_raw.svg, csg_fandisk_cylinder.svg,"
  echo "csg_rocker_sphere.svg, csg_spot_spot.svg (in docs/)."
  echo
  ./build/bench/bench_csg --plots docs
  echo
  echo "## Game edits on the default landscape (issue 4)"
  echo
  ./build/bench/bench_csg_game
  echo
  echo "## Game queries against Embree (issue 5)"
  echo
  ./build/bench/bench_query
  echo
  echo "## Pathfinding against Recast/Detour (issue 6)"
  echo
  ./build/bench/bench_nav
  echo
  echo "## Voxel export against OpenVDB's solid voxelization (issue 7)"
  echo
  ./build/bench/bench_voxelize
  echo
  echo "## Cone-traced GI against a path-traced reference (issue 8)"
  echo
  if [ -x ./build/bench/bench_gi ]; then ./build/bench/bench_gi; else echo "(bench_gi not built: needs LDC_WITH_VULKAN and Embree)"; fi
} > docs/benchmarks.md.tmp
mv docs/benchmarks.md.tmp docs/benchmarks.md
echo "wrote docs/benchmarks.md"
