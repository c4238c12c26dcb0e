#!/usr/bin/env bash
# slurm-merge-ready.sh (issue 58), without a cluster: the window task that finds every window's
# stamp runs the merge, once; a task that finds a stamp missing, or the output newer than every
# stamp, does nothing; tasks ending together merge once (the lock); a failed merge fails the task.
#
#   tests/slurm/merge_ready_test.sh WORK_DIR
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
ready=$here/../../pipelines/slurm-merge-ready.sh
work=$1
fail() { echo "merge_ready_test: FAIL: $*" >&2; exit 1; }

rm -rf "$work"
mkdir -p "$work/windows"
dir=$work/windows out=$work/merged count=$work/merges
# The "merge": counts its runs, takes a moment (so that tasks ending together overlap in it),
# then writes the output.
merge() { "$ready" "$dir" 3 "$out" sh -c "echo x >> '$count'; sleep 0.2; echo merged > '$out'" 2>/dev/null; }
runs() { [ -e "$count" ] && wc -l <"$count" | tr -d ' ' || echo 0; }

touch "$dir/.window-0-of-3" "$dir/.window-2-of-3"
merge || fail "a task with a window still running failed"
[ "$(runs)" = 0 ] && [ ! -e "$out" ] || fail "merged with window 1 of 3 missing"

sleep 0.01
touch "$dir/.window-1-of-3"
merge || fail "the last window's task failed to merge"
[ "$(runs)" = 1 ] && [ "$(cat "$out")" = merged ] || fail "the last window's task did not merge (runs: $(runs))"

merge || fail "a task after the merge failed"
[ "$(runs)" = 1 ] || fail "merged again although the output is newer than every stamp"

# Three tasks ending together, the output gone: one merge, whichever task takes the lock first.
rm -f "$out" "$count"
merge & a=$!
merge & b=$!
merge & c=$!
wait "$a" && wait "$b" && wait "$c" || fail "a task ending with the others failed"
[ "$(runs)" = 1 ] || fail "tasks ending together merged $(runs) times"

# A window re-run (its stamp newer than the output) merges again.
sleep 0.01
touch "$dir/.window-0-of-3"
merge || fail "the re-run window's task failed"
[ "$(runs)" = 2 ] || fail "a window re-run after the merge was not merged again"

# A failed merge fails the task, with its exit code.
rm -f "$out"
set +e
"$ready" "$dir" 3 "$out" sh -c 'exit 3' 2>/dev/null
rc=$?
set -e
[ "$rc" = 3 ] || fail "a failed merge gave exit $rc, expected the merge's 3"
echo "merge_ready_test: the last window merges once, the others and tasks after it do nothing"
