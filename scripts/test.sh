#!/usr/bin/env bash
# Installs what is needed, builds, and runs the whole test suite under ctest.
# Every optional suite is required (LDC_REQUIRE_ALL) and warnings are errors
# (LDC_WERROR); the run fails if any test was skipped or any suite has no tests.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DLDC_REQUIRE_ALL=ON -DLDC_WERROR=ON
jobs=$(nproc 2>/dev/null || echo 2)
log=build/ctest.log
ctest --test-dir build --output-on-failure -j "$jobs" --no-tests=error 2>&1 | tee "$log"
if grep -q "The following tests did not run" "$log"; then
  echo "test.sh: some tests were skipped (listed above); every suite must run" >&2
  exit 1
fi
for label in unit tool capi cgal embree gi vdb recast install docs; do
  count=$(ctest --test-dir build -N -L "^${label}\$" | sed -n 's/^Total Tests: //p')
  if [ "${count:-0}" -eq 0 ]; then
    echo "test.sh: the '$label' suite has no tests" >&2
    exit 1
  fi
done
