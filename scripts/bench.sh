#!/usr/bin/env bash
# Builds the benchmarks and writes their tables to docs/benchmarks.md.
# Run on an otherwise idle machine: the tables are wall-clock timings.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# Benchmark-only peers of bench_boolean_process, never needed to build or test
# ldc (without them it skips their rows): native Manifold, built once from
# ../shared/peers into a prefix outside the repository (LDC_PEERS_PREFIX,
# default ../peers-prefix), and npm manifold-3d (bench/js, pinned by its lock).
peers_prefix=${LDC_PEERS_PREFIX:-$(realpath -m ../peers-prefix)}
manifold_args=()
if [ ! -f "$peers_prefix/lib/cmake/manifold/manifoldConfig.cmake" ] && [ -f ../shared/peers/build-manifold.sh ]; then
  bash ../shared/peers/build-manifold.sh "$peers_prefix" || echo "bench.sh: the Manifold build failed; its rows are skipped"
fi
if [ -f "$peers_prefix/lib/cmake/manifold/manifoldConfig.cmake" ]; then
  manifold_args=(-Dmanifold_DIR="$peers_prefix/lib/cmake/manifold")
fi
(cd bench/js && npm ci --no-audit --no-fund --silent) || echo "bench.sh: npm ci in bench/js failed; manifold-3d rows are skipped"
bash scripts/build.sh -DLDC_BUILD_BENCH=ON ${manifold_args[@]+"${manifold_args[@]}"}
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
  echo "## Mesh booleans as users run them: whole processes against CGAL and Manifold (issue 19)"
  echo
  echo "Plots of error against time and against triangles: bool_process_<case>_time.svg and"
  echo "bool_process_<case>_tris.svg; every row in bool_process.csv (in docs/). ldc rows: the defaults (adaptive)"
  echo "and \`--max-error 0\` (uniform)."
  echo
  ./build/bench/bench_boolean_process --plots docs --ldc-args "" --ldc-args "--max-error 0"
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
