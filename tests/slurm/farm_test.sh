#!/usr/bin/env bash
# The farm test (ctest label `farm`, issue 17): the bundled scene's 24 frames through
# pipelines/slurm.mk on a real single-node Slurm cluster (tests/slurm/cluster.sh), SHARDS=4,
# WAIT=1, against animation.mk's frames on this machine:
#   1. with rad-global in 3 time windows and a merge (GLOBAL_WINDOWS=3), global.rlh is the single
#      run's byte for byte, rad-intervals' item buffers are drawn in 3 windows and its movies
#      decided from their counts (INTERVAL_WINDOWS=3), each merge run once by the window task
#      that ended last (no merge job), and every frame's pixels (EXR and PNG) are bit-identical to
#      animation.mk's (the frame files differ only in their provenance, which records each
#      task's own command line and paths); the movies of more than MOVIE_PIECE_KEYS=4 keys were
#      baked in pieces and merged by the movies tasks themselves, no merge stage (issue 58),
#      and every output (global.rlh, intervals.rti, movies, frames) is animation.mk's
#      (pipelines/same_outputs.py); the mp4 joined from the compose tasks' segments holds every
#      frame;
#   2. a movies task killed mid-run makes WAIT fail with one line naming the stage, the task and
#      its log; the dependent jobs are cancelled; nothing downstream is marked done; the re-run
#      submits only the killed shard and ends with the same frames;
#   3. an up-to-date run submits nothing, and a change of COMPOSE_FLAGS only the frames on;
#   4. with MOVIE_PIECE_COSTS (the first run's shard reports), only the costly movies are cut,
#      dealt by cost, merged by the tasks, and every output is still animation.mk's.
# Needs root (it starts slurmctld/slurmd): without it, skipped with one line (exit 77).
#
#   tests/slurm/farm_test.sh BIN_DIR WORK_DIR
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=$(cd "$1" && pwd)
work=$2

if [ "$(id -u)" -ne 0 ]; then
  echo "farm_test: skipped: needs root to start a local Slurm cluster (running as uid $(id -u))"
  exit 77
fi

fail() { echo "farm_test: FAIL: $*" >&2; exit 1; }

# cluster.sh's ports are fixed: one such cluster per host.
if pgrep -x slurmctld >/dev/null; then
  fail "a slurmctld is already running on this host; stop it first (tests/slurm/cluster.sh down)"
fi
rm -rf "$work"
mkdir -p "$work"
export RAD_SLURM_DIR=$work/cluster
started=0
cleanup() { [ "$started" = 0 ] || "$here/cluster.sh" down >/dev/null 2>&1 || true; }
trap cleanup EXIT
"$here/cluster.sh" up >/dev/null
started=1
# shellcheck disable=SC1091
. "$RAD_SLURM_DIR/env"

cd "$root"
common=(SCENE=pipelines/scenes/cornell-moving.gltf FRAMES=0-23 "BIN=$bin")
make -s -f pipelines/animation.mk "${common[@]}" "OUT=$work/local" >/dev/null 2>&1 ||
  fail "animation.mk failed"

# The same pixels, frame by frame (oiiotool --diff with zero tolerance: any bit of any pixel).
same_frames() {
  local a=$1 b=$2 n=0
  for f in "$a"/frames/*.exr "$a"/frames/*.png; do
    local g
    g=$b/frames/$(basename "$f")
    [ -e "$g" ] || fail "$g is missing"
    oiiotool --fail 0 --failpercent 0 --warn 0 "$f" "$g" --diff >/dev/null 2>&1 ||
      fail "$g differs from $f"
    n=$((n + 1))
  done
  [ "$n" -eq 48 ] || fail "$a has $n frame files, expected 48"
}

# 1. A whole run, rad-global in 3 time windows and their merge.
make -s -f pipelines/slurm.mk "${common[@]}" "OUT=$work/farm" SHARDS=4 GLOBAL_WINDOWS=3 INTERVAL_WINDOWS=3 WAIT=1 \
  MOVIE_PIECE_KEYS=4 2>"$work/farm.err" || fail "slurm.mk WAIT=1 failed: $(tail -1 "$work/farm.err")"
same_frames "$work/local" "$work/farm"
if grep -q "slurm.mk: \(movies\|global\|intervals\)-merge submitted" "$work/farm.err"; then
  fail "a merge job was submitted: the window and movies tasks merge themselves: $(grep -- '-merge submitted' "$work/farm.err")"
fi
# rad-global's and rad-intervals' merges ran once each, in the window task that ended last.
for stage in global intervals; do
  n=$(cat "$work"/farm/logs/${stage}_*.log | grep -c "^slurm-merge-ready: every window .* merging" || true)
  [ "$n" = 1 ] || fail "$stage's windows were merged $n times by their tasks (expected once: logs/${stage}_*.log)"
done
merged=$(cat "$work"/farm/logs/movies_*.log | sed -n 's/^rad-movies: merged \([0-9]*\) movies.*/\1/p' |
  awk '{n += $1} END {print n + 0}')
[ "$merged" -gt 0 ] || fail "no movie was baked in pieces and merged by a movies task (logs/movies_*.log)"
if ls "$work/farm/movies" | grep -q 'piece\|merge-lock'; then fail "movie pieces or locks left after the merge"; fi
python3 pipelines/same_outputs.py "$work/local" "$work/farm" >"$work/same.out" ||
  fail "slurm.mk's outputs differ from animation.mk's: $(cat "$work/same.out")"
echo "farm_test: $merged movies baked in pieces and merged; $(tail -1 "$work/same.out")"
# The mp4 joined from the compose tasks' segments holds every frame, at FPS.
probe=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames,r_frame_rate \
  -of csv=p=0 "$work/farm/movie.mp4")
[ "$probe" = "24/1,24" ] || fail "movie.mp4 from segments: $probe (expected 24/1,24: 24 frames at 24 fps)"
# The merged global.rlh is the one rad-global writes in one piece, byte for byte (provenance
# included: the merge records the single run's command line, which names this OUT).
global_cmd=$(make -s -f pipelines/animation.mk "${common[@]}" "OUT=$work/farm" stage-commands |
  awk -F'\t' '$1 == "global" {print $2}')
mv "$work/farm/global.rlh" "$work/farm/global-merged.rlh"
mv "$work/farm/global-report.json" "$work/farm/global-merged-report.json"
sh -c "$global_cmd" 2>/dev/null || fail "the single rad-global run failed: $global_cmd"
cmp -s "$work/farm/global.rlh" "$work/farm/global-merged.rlh" ||
  fail "the merge of 3 windows differs from the single run's global.rlh"
mv -f "$work/farm/global-merged.rlh" "$work/farm/global.rlh"
mv -f "$work/farm/global-merged-report.json" "$work/farm/global-report.json"
echo "farm_test: rad-global in 3 windows merges into the single run's global.rlh, byte for byte"
for f in movie.mp4 contact-sheet.png movies/.done frames/.done logs/movies_3.log logs/compose_3.log; do
  [ -s "$work/farm/$f" ] || [ -e "$work/farm/$f" ] || fail "$work/farm/$f is missing"
done
echo "farm_test: 24 frames through slurm.mk (SHARDS=4) have animation.mk's pixels"

# 3. Up to date: nothing is submitted.
make -s -f pipelines/slurm.mk "${common[@]}" "OUT=$work/farm" SHARDS=4 MOVIE_PIECE_KEYS=4 WAIT=1 2>"$work/again.err" ||
  fail "the up-to-date re-run failed"
if grep -q submitted "$work/again.err"; then fail "an up-to-date run submitted: $(cat "$work/again.err")"; fi
# A parameter change submits what animation.mk would re-run: COMPOSE_FLAGS, only the frames on.
make -s -f pipelines/slurm.mk "${common[@]}" "OUT=$work/farm" SHARDS=4 MOVIE_PIECE_KEYS=4 COMPOSE_FLAGS="--exposure 0.5" WAIT=1 \
  2>"$work/change.err" || fail "the re-run with other COMPOSE_FLAGS failed"
stages=$(sed -n 's/^slurm.mk: \([a-z0-9-]*\) submitted:.*/\1/p' "$work/change.err" | tr '\n' ' ')
[ "$stages" = "compose frames-done mp4 contact-sheet " ] ||
  fail "COMPOSE_FLAGS=--exposure 0.5 submitted: $stages (expected compose frames-done mp4 contact-sheet)"
echo "farm_test: an up-to-date run submits nothing; COMPOSE_FLAGS submits only: $stages"

# 2. Kill movies task 1 mid-run: submit without waiting, kill its rad-movies once it runs.
out=$work/kill
make -s -f pipelines/slurm.mk "${common[@]}" "OUT=$out" SHARDS=4 2>"$work/kill.err"
killed=0
for _ in $(seq 1 1200); do
  if pids=$(pgrep -f -- "rad-movies .*-o $out/movies .*--shard 1/4"); then
    echo "$pids" | xargs kill -9 && killed=1 && break
  fi
  sleep 0.05
done
[ "$killed" = 1 ] || fail "movies task 1 never ran"
set +e
"$root/pipelines/slurm-wait.sh" "$out/slurm-jobs" "$out/logs" 2>"$work/wait.err"
rc=$?
set -e
[ "$rc" -ne 0 ] || fail "WAIT succeeded although a movies task was killed"
# Besides its progress lines ("waiting (N s): stages"), one line: stage, task, log.
grep -v '^slurm.mk: waiting (' "$work/wait.err" >"$work/wait.line" || true
[ "$(wc -l <"$work/wait.line")" -eq 1 ] || fail "WAIT's failure is not one line: $(cat "$work/wait.err")"
grep -q "^slurm.mk: movies task 1 .*$out/logs/movies_1.log" "$work/wait.line" ||
  fail "WAIT's line does not name the stage, task and log: $(cat "$work/wait.line")"
[ ! -e "$out/movies/.done" ] || fail "movies/.done written although a shard failed"
[ ! -e "$out/frames/.done" ] || fail "frames/.done written although a shard failed"
[ ! -e "$out/logs/compose_0.log" ] || fail "compose ran although a shard failed"
squeue -h -o '%F' | grep -qxFf <(awk '{print $2}' "$out/slurm-jobs") &&
  fail "jobs of the failed run are left in the queue"
echo "farm_test: killed movies task 1: $(cat "$work/wait.line")"

make -s -f pipelines/slurm.mk "${common[@]}" "OUT=$out" SHARDS=4 WAIT=1 2>"$work/rerun.err" ||
  fail "the re-run failed: $(tail -1 "$work/rerun.err")"
grep -q "slurm.mk: movies submitted: job [0-9]*, tasks 1\(,\|$\)" "$work/rerun.err" ||
  fail "the re-run did not submit exactly movies task 1: $(grep movies "$work/rerun.err")"
if grep -q "global submitted\|intervals submitted" "$work/rerun.err"; then
  fail "the re-run resubmitted an up-to-date stage"
fi
same_frames "$work/local" "$out"
echo "farm_test: the re-run submitted only movies task 1 and gave the same frames"

# 4. The cut by known cost (issue 58; rad-movies --piece-costs): the first run's shard reports
# cut the movies that took more than MOVIE_PIECE_SECONDS, the others whole, and the movies are
# animation.mk's. The cut changes no byte of them, so an up-to-date movies stage is not baked
# again for it: the movies are cleaned first.
costs=$(ls "$work"/farm/movies-report-*of4.json | tr '\n' ' ')
pipelines/clean.sh "$work/farm" movies
make -s -f pipelines/slurm.mk "${common[@]}" "OUT=$work/farm" SHARDS=4 MOVIE_PIECE_KEYS=4 \
  MOVIE_PIECE_COSTS="$costs" MOVIE_PIECE_SECONDS=0.5 WAIT=1 2>"$work/cost.err" ||
  fail "slurm.mk with MOVIE_PIECE_COSTS failed: $(tail -1 "$work/cost.err")"
grep -q "slurm.mk: movies submitted" "$work/cost.err" || fail "the cut by cost baked no movie again"
ls "$work"/farm/movies/.pshard4cost*-0-of-4 >/dev/null 2>&1 || fail "the shards' stamps do not name the cut"
# This run's shard reports: pieces of the costly movies, the cheap ones whole.
read -r pieces whole < <(python3 -c 'import json, sys
units = [w for f in sys.argv[1:] for w in json.load(open(f))["work_seconds"]]
print(sum(w["piece"] >= 0 for w in units), sum(w["piece"] < 0 for w in units))' "$work"/farm/movies-report-*of4.json)
[ "$pieces" -gt 0 ] || fail "the cut by cost cut no movie (MOVIE_PIECE_SECONDS=0.5)"
[ "$whole" -gt 0 ] || fail "the cut by cost cut every movie: not by cost"
if ls "$work/farm/movies" | grep -q 'piece\|merge-lock'; then fail "movie pieces or locks left after the merge"; fi
python3 pipelines/same_outputs.py "$work/local" "$work/farm" >"$work/same-cost.out" ||
  fail "with the cut by cost, slurm.mk's outputs differ from animation.mk's: $(cat "$work/same-cost.out")"
echo "farm_test: the cut by cost: $pieces pieces and $whole whole movies; $(tail -1 "$work/same-cost.out")"
