#!/usr/bin/env bash
# slurm.mk: run by each window task of a split stage (rad-global's time windows, rad-intervals'
# windows of item buffers) after its window and stamp: the task that finds every window's stamp
# DIR/.window-I-of-N runs the merge COMMAND, so the merge waits for no job of its own and its
# scheduling latency is off the critical path (issue 58; the movies tasks merge their pieces
# alike). Under a lock on DIR/.merge-lock, so two tasks that end together merge once: the second
# finds OUTPUT newer than every stamp and does nothing. A task that finds a stamp missing leaves
# the merge to the task that will write it. A failed merge fails this task (its log has why); a
# re-run finds every window done and submits the merge as a job of its own.
#
#   pipelines/slurm-merge-ready.sh DIR N OUTPUT COMMAND [ARGUMENT]...
set -euo pipefail
dir=$1 n=$2 output=$3
shift 3

exec 9>"$dir/.merge-lock"
flock 9
fresh=1
[ -e "$output" ] || fresh=0
for ((i = 0; i < n; ++i)); do
  stamp=$dir/.window-$i-of-$n
  [ -e "$stamp" ] || exit 0  # a window still running merges when it ends
  [ "$fresh" = 1 ] && [ "$output" -nt "$stamp" ] || fresh=0
done
[ "$fresh" = 0 ] || exit 0
echo "slurm-merge-ready: every window of $dir is done: merging into $output" >&2
"$@"
