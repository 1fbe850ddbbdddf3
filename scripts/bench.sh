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
# One section per benchmark, each stamped with the load average before and
# after it (a busy machine makes the timings worthless: the reader can see
# it) and the thread counts of ldc and the peers, which each bench also
# states in its table notes.
load() { cut -d' ' -f1-3 /proc/loadavg; }
section() {  # section "heading" "threads" command...
  local heading=$1 threads=$2
  shift 2
  local before t0
  before=$(load)
  t0=$(date +%s)
  echo "## $heading"
  echo
  echo "Threads: $threads. Load average (1, 5, 15 min) before: $before."
  echo
  "$@"
  echo
  echo "Load average after: $(load); this section took $(( $(date +%s) - t0 )) s."
  echo
  echo "$heading: done in $(( $(date +%s) - t0 )) s" >&2
}
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
git diff --quiet HEAD 2>/dev/null || commit="$commit (with uncommitted changes)"
cpu=$(grep -m1 "model name" /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')
{
  echo "# Benchmarks"
  echo
  echo "Written by \`scripts/bench.sh\` in one run; every table compares ldc with a peer library measured in the same run."
  echo
  echo "- commit: $commit"
  echo "- machine: $cpu, $(nproc) hardware threads, $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo)"
  echo "- started: $(date -u '+%Y-%m-%d %H:%M UTC'), load average $(load)"
  echo
  section "LDC build (issue 2)" "ldc and OpenVDB 1 and 2 (both columns)" ./build/bench/bench_build
  section "Dual contouring: remesh time against error (issue 3)" "ldc and OpenVDB 1 and 2 (both columns)" \
    ./build/bench/bench_contour --plots docs
  section "Mesh booleans against CGAL corefinement and OpenVDB (issue 4)" "ldc and OpenVDB 1 and 2, CGAL 1" \
    ./build/bench/bench_csg --plots docs
  section "Mesh booleans as users run them: whole processes against CGAL and Manifold (issue 19)" \
    "ldc and native Manifold 2, CGAL and manifold-3d 1" \
    ./build/bench/bench_boolean_process --plots docs --ldc-args "" --ldc-args "--max-error 0"
  section "Game edits on the default landscape (issue 4)" "1 and 2 (column)" ./build/bench/bench_csg_game
  section "Levels of detail: every 2^k-th ray (issue 21)" "2" ./build/bench/bench_lod
  section "Large worlds: paging and saving per chunk (issue 21)" "1 (throughput: 1 and 2)" ./build/bench/bench_store
  section "Game queries against Embree (issue 5)" "ldc and Embree 1 and 2 (columns)" ./build/bench/bench_query
  section "Pathfinding against Recast/Detour (issue 6)" "ldc and Detour 1" ./build/bench/bench_nav
  section "Voxel export against OpenVDB's solid voxelization (issue 7)" "ldc and OpenVDB 1 and 2 (columns)" \
    ./build/bench/bench_voxelize
  if [ -x ./build/bench/bench_gi ]; then
    section "Cone-traced GI against a path-traced reference (issue 8)" "CPU engine and path tracer: every core; the Vulkan engine on its device" \
      ./build/bench/bench_gi
    section "Cone-traced GI in whole images: caves, tunnels, sealed rooms (issue 25)" "CPU engine and path tracer: every core; the Vulkan engine on its device" \
      ./build/bench/bench_gi 0 256 images docs/images
  else
    echo "(bench_gi not built: needs LDC_WITH_VULKAN and Embree)"
  fi
  echo "Finished: $(date -u '+%Y-%m-%d %H:%M UTC'), load average $(load)."
  # GI on a GPU comes from its own recorded runs on lent machines (this machine has none).
  if [ -f docs/gpu-runs.md ]; then
    echo
    cat docs/gpu-runs.md
  fi
} > docs/benchmarks.md.tmp
mv docs/benchmarks.md.tmp docs/benchmarks.md
echo "wrote docs/benchmarks.md"
