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
} > docs/benchmarks.md.tmp
mv docs/benchmarks.md.tmp docs/benchmarks.md
echo "wrote docs/benchmarks.md"
