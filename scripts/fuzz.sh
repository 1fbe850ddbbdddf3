#!/usr/bin/env bash
# Builds the libFuzzer targets with clang and runs each for a bounded time.
# Usage: scripts/fuzz.sh [seconds per target, default 60]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
# -O1 with line tables: about half the compile time of -O2 -g; reports still name file and line.
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
  -DLDC_BUILD_FUZZERS=ON -DLDC_BUILD_TESTS=OFF -DLDC_BUILD_TOOLS=OFF \
  -DLDC_BUILD_CAPI=OFF -DLDC_BUILD_EXAMPLES=OFF -DLDC_INSTALL=OFF >/dev/null
targets=(fuzz_ldc_load fuzz_mesh_parsers fuzz_edits fuzz_json_inputs)
# Only the fuzzers and what they link (nav for the path inputs; not voxelize, GI and their shaders).
cmake --build build-fuzz -j "$(nproc 2>/dev/null || echo 2)" --target "${targets[@]}"
for target in "${targets[@]}"; do
  corpus=$(mktemp -d)
  cp fuzz/corpus/${target#fuzz_}/* "$corpus"/ 2>/dev/null || true
  echo "fuzzing $target for ${seconds}s"
  log=$(mktemp)
  # The whole log when the fuzzer finds anything (the report and the input that
  # caused it, saved as crash-* here); the final stats otherwise.
  if ! ./build-fuzz/fuzz/$target "$corpus" -max_total_time="$seconds" -rss_limit_mb=2048 \
      -malloc_limit_mb=1024 -timeout=10 -print_final_stats=1 >"$log" 2>&1; then
    cat "$log"
    echo "fuzz.sh: $target found a failure (its input is saved as crash-*/timeout-*/oom-* here);" \
      "add it to fuzz/corpus/${target#fuzz_}/ and as a named regression test" >&2
    exit 1
  fi
  tail -n 12 "$log"
  rm -rf "$corpus" "$log"
done
