#!/usr/bin/env bash
# Configures and builds ldc (Release with asserts on) into ./build.
# Extra arguments go to CMake, e.g. scripts/build.sh -DLDC_BUILD_BENCH=ON
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DLDC_ASSERTS=ON "$@"
cmake --build build -j "$jobs"
