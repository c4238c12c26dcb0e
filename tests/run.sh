#!/usr/bin/env bash
# The README's test command: install what is missing, build the tools and the tests, run every
# ctest test, then fuzz every reader for a short fixed time (tests/fuzz/run.sh: a second, clang
# build in build-fuzz/).
# Extra arguments go to ctest (for example: tests/run.sh -L unit) and skip the fuzzing, as does
# RAD_SKIP_FUZZ=1.
set -euo pipefail
cd "$(dirname "$0")/.."
pipelines/bootstrap.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs" "$@"
if [ $# -eq 0 ] && [ "${RAD_SKIP_FUZZ:-0}" != 1 ]; then
  tests/fuzz/run.sh
fi
