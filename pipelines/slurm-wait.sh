#!/usr/bin/env bash
# slurm.mk's WAIT=1: blocks until every job this make run submitted has left the queue, then
# checks each task's exit file (slurm-task.sh) and exits non-zero with one line naming the
# first failed stage, its task and its log.
#
#   pipelines/slurm-wait.sh SUBMITTED LOGS
#
# SUBMITTED has one line per job: STAGE JOBID TASKS (TASKS: comma-separated array indices, or 0).
set -uo pipefail
submitted=$1 logs=$2
[ -s "$submitted" ] || exit 0
ids=$(awk '{print $2}' "$submitted" | sort -u)

last_report=0
start=$(date +%s)
while :; do
  if ! queue=$(squeue -h -o '%F %r' 2>&1); then
    echo "slurm.mk: squeue failed: $queue" >&2
    exit 1
  fi
  ours=$(awk 'NR==FNR {want[$1]=1; next} ($1 in want)' <(echo "$ids") <(echo "$queue"))
  [ -n "$ours" ] || break
  # A job whose dependency failed is cancelled by --kill-on-invalid-dep; should a site's Slurm
  # leave it pending for ever instead, cancel it here rather than wait for ever.
  stuck=$(echo "$ours" | awk '$2 == "DependencyNeverSatisfied" {print $1}' | sort -u)
  [ -z "$stuck" ] || echo "$stuck" | xargs scancel
  now=$(date +%s)
  if [ $((now - last_report)) -ge 30 ]; then
    stages=$(awk 'NR==FNR {want[$1]=1; next} ($2 in want) {print $1}' <(echo "$ours" | awk '{print $1}') \
      "$submitted" | sort -u | tr '\n' ' ')
    echo "slurm.mk: waiting ($((now - start)) s): ${stages% }" >&2
    last_report=$now
  fi
  sleep 1
done

# The first failure in submission order (stage order) is the cause; the tasks after it that
# never ran were cancelled because of it.
failed="" never=0
while read -r stage job tasks; do
  for t in ${tasks//,/ }; do
    log=$logs/${stage}_$t.log exitfile=$logs/${stage}_$t.exit
    if [ -e "$exitfile" ]; then
      read -r rc _ <"$exitfile"
      [ "$rc" = 0 ] || { [ -n "$failed" ] || failed="$stage task $t failed (exit $rc): $log"; }
    elif [ -e "$log" ]; then
      [ -n "$failed" ] || failed="$stage task $t was killed before it finished (job $job): $log"
    else
      never=$((never + 1))
    fi
  done
done < "$submitted"
if [ -n "$failed" ]; then
  [ "$never" -eq 0 ] || failed="$failed ($never dependent tasks cancelled)"
  echo "slurm.mk: $failed" >&2
  exit 1
fi
if [ "$never" -ne 0 ]; then
  echo "slurm.mk: $never tasks never ran (cancelled?); see squeue/sacct and $logs" >&2
  exit 1
fi
exit 0
