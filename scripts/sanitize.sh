#!/usr/bin/env bash
# Builds with AddressSanitizer + UndefinedBehaviorSanitizer and runs the unit
# tests and the C API test (tests/capi/test_capi.c through libldc_c.so).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLDC_SANITIZE=ON \
  -DLDC_BUILD_TOOLS=OFF -DLDC_BUILD_EXAMPLES=OFF -DLDC_INSTALL=OFF >/dev/null
cmake --build build-asan -j "$jobs" --target ldc_tests ldc_capi_test
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan -L 'unit|capi' --output-on-failure -j "$jobs"
