#!/usr/bin/env bash
# Fuzzes every reader (README "Reliability"): installs clang-14 if missing, builds the harnesses
# into build-fuzz/ (clang, libFuzzer + ASan + UBSan; only the readers' libraries, not the tools),
# makes the seeds with build/bin's tools (run pipelines/bootstrap.sh first) and runs the ctest
# label `fuzz`, then prints each harness's executions and crashes.
#   FUZZ_SECONDS  time cap per harness (default 60)
#   FUZZ_RUNS     executions per harness (default 20000; -1: no limit but the time)
# tests/run.sh runs it after the other tests; make -f pipelines/bench.mk fuzz runs it long.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${FUZZ_SECONDS:-60}
runs=${FUZZ_RUNS:-20000}

pipelines/apt_install.sh clang-14 libclang-rt-14-dev

launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B build-fuzz -DRAD_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 "${launcher[@]}" \
  -DRAD_SEED_BIN="$PWD/build/bin" -DRAD_FUZZ_SECONDS="$seconds" -DRAD_FUZZ_RUNS="$runs" >/dev/null
cmake --build build-fuzz -j"$(nproc 2>/dev/null || echo 2)"

rm -rf build-fuzz/fuzz-work
status=0
ctest --test-dir build-fuzz -L fuzz --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" || status=$?
cat build-fuzz/fuzz-work/*/summary.txt 2>/dev/null || true
exit "$status"
