#!/usr/bin/env bash
# slurm.mk: which pieces of a split stage (movie shards, frame chunks) must run. A piece is done
# when its stamp DIR/.KIND-I-of-N exists, is newer than every prerequisite of the stage, and no
# stage upstream of it was submitted in this make run (its inputs are about to change). If any
# stamp is stale or of another split, the folder is emptied of the pipeline's files (clean.sh):
# they came from other inputs. Prints the indices to run, comma-separated (empty: every piece is done).
#
#   pipelines/slurm-pieces.sh DIR KIND N SUBMITTED "UPSTREAM STAGES" PREREQUISITE...
set -euo pipefail
dir=$1 kind=$2 n=$3 submitted=$4 upstream=$5
shift 5

stale=0
if [ -s "$submitted" ] && awk -v want=" $upstream " 'index(want, " " $1 " ") {found=1} END {exit !found}' \
    "$submitted"; then
  stale=1
fi
have=0
for stamp in "$dir/.$kind-"*; do
  [ -e "$stamp" ] || continue
  have=1
  case ${stamp##*/} in .$kind-*-of-$n) ;; *) stale=1 ;; esac
  for p in "$@"; do
    if [ -e "$p" ] && ! [ "$stamp" -nt "$p" ]; then stale=1; fi
  done
done
if [ "$stale" = 1 ] || [ "$have" = 0 ]; then "$(dirname "$0")/clean.sh" "$(dirname "$dir")" "$(basename "$dir")"; fi
mkdir -p "$dir"

missing=()
for ((i = 0; i < n; ++i)); do
  [ -e "$dir/.$kind-$i-of-$n" ] || missing+=("$i")
done
(IFS=,; echo "${missing[*]}")
