#!/usr/bin/env bash
# The README's test command: install what is missing, build, run every ctest test.
# Extra arguments go to ctest (for example: tests/run.sh -L unit).
set -euo pipefail
cd "$(dirname "$0")/.."
pipelines/bootstrap.sh
ctest --test-dir build --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" "$@"
