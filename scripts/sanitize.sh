#!/usr/bin/env bash
# Builds with AddressSanitizer + UndefinedBehaviorSanitizer and runs the unit tests.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLDC_SANITIZE=ON \
  -DLDC_BUILD_TOOLS=OFF >/dev/null
cmake --build build-asan -j "$(nproc 2>/dev/null || echo 2)" --target ldc_tests
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan -L unit --output-on-failure -j "$(nproc 2>/dev/null || echo 2)"
