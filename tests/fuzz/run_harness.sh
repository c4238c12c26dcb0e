#!/usr/bin/env bash
# Runs one libFuzzer harness on its seeds and prints how many inputs it executed.
# Usage: tests/fuzz/run_harness.sh HARNESS SEEDS_DIR WORK_DIR SECONDS [RUNS] [SEED]
#   SECONDS  -max_total_time; RUNS  -runs (omit or -1 for no limit but the time);
#   SEED     libFuzzer's random seed (0 or omitted: a new one each run). The ctest runs fix it,
#            so CI explores the same inputs each time and a red run is reproducible.
# New interesting inputs go to WORK_DIR/corpus (the seeds are never written), a crashing input to
# WORK_DIR/crashes/ (copy it to tests/data/fuzz-regressions/<reader>/ to keep it replayed).
# Exits non-zero on a crash, a leak, a timeout (30 s per input), an input taking over 2 GB
# (-rss_limit_mb; the EXR readers bound what a header may declare by the file's size first,
# formats/exr_header_scan.h) or undefined behaviour.
set -uo pipefail
harness=$1
seeds=$2
work=$3
seconds=$4
runs=${5:--1}
seed=${6:-0}
name=$(basename "$harness")
mkdir -p "$work/corpus" "$work/crashes"
log=$work/$name.log
"$harness" -max_total_time="$seconds" -runs="$runs" -seed="$seed" -timeout=30 -rss_limit_mb=2048 \
  -print_final_stats=1 -artifact_prefix="$work/crashes/" "$work/corpus" "$seeds" >"$log" 2>&1
status=$?
executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
# slow-unit-* files are kept for a look but are not failures.
crashes=$(find "$work/crashes" -type f ! -name 'slow-unit-*' | wc -l)
echo "$name: ${executions:-?} executions, $crashes crash(es), exit $status" | tee "$work/summary.txt"
if [ "$status" -ne 0 ]; then
  tail -n 60 "$log"
  echo "$name: reproducer(s):" $(find "$work/crashes" -type f ! -name 'slow-unit-*') | tee -a "$work/summary.txt"
fi
exit "$status"
