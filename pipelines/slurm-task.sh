#!/usr/bin/env bash
# One task of a slurm.mk job: runs its command (one shell string, which may name
# $SLURM_ARRAY_TASK_ID) and records its exit code and wall seconds next to its log, as
# LOGS/STAGE_TASK.exit ("CODE SECONDS"; pipelines/farm_model.py reads the seconds),
# for slurm-wait.sh to tell a failed task from one that never ran (cancelled: no log at all)
# and from one killed mid-run (a log but no exit file).
#
#   sbatch ... --output=LOGS/STAGE_%a.log pipelines/slurm-task.sh LOGS STAGE 'COMMAND'
set -uo pipefail
logs=$1 stage=$2 command=$3
task=${SLURM_ARRAY_TASK_ID:-0}
echo "slurm-task: $stage task $task on $(hostname -s), job ${SLURM_JOB_ID:-?}: $command" >&2
start=$(date +%s.%N)
sh -c "$command"
rc=$?
seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')
# The exit file is written atomically: a half-written one would read as a wrong code.
printf '%d %s\n' "$rc" "$seconds" > "$logs/${stage}_$task.exit.tmp" && mv -f "$logs/${stage}_$task.exit.tmp" "$logs/${stage}_$task.exit"
exit "$rc"
