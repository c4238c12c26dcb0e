#!/usr/bin/env bash
# The pipeline's variables, checked while the Makefile is read and before anything runs or is
# written (stages.mk). Prints one line saying what is wrong, or nothing; the Makefile stops on it.
#
#   pipelines/check-variables.sh REPO SCENE OUT BIN FRAMES SIZE FPS QUALITY
#
# Paths (SCENE, OUT, BIN) may hold only letters, digits, `. _ - + @ /` and non-ASCII bytes:
# Make splits file names at spaces and gives `:`, `%`, `=`, `#`, `$` meanings of its own, and
# the stage command lines pass paths to a shell, so a path outside this set could not be
# carried through every rule safely. OUT is refused where a run or `make clean` could harm what
# is not the pipeline's own: the root, the home folder, the repository or a folder holding it,
# and an existing file that is not a folder.
set -u
repo=$1 scene=$2 out=$3 bin=$4 frames=$5 size=$6 fps=$7 quality=$8

fail() {
  printf '%s\n' "$1"
  exit 0
}

check_path() {
  local name=$1 value=$2 rest
  [ -n "$value" ] || fail "$name is empty; give a path"
  rest=$(printf '%s' "$value" | LC_ALL=C tr -d 'A-Za-z0-9._/+@\200-\377-')
  [ -z "$rest" ] || fail "$name='$value': '${rest:0:1}' is not allowed in a path here (only letters, digits, . _ - + @ / and non-ASCII); rename the folder or link it"
}

check_path SCENE "$scene"
check_path OUT "$out"
check_path BIN "$bin"

abs_out=$(realpath -m -- "$out")
abs_repo=$(realpath -m -- "$repo")
[ "$abs_out" != / ] || fail "OUT=$out is the root folder; give a folder of the run's own"
if [ -n "${HOME:-}" ] && [ "$abs_out" = "$(realpath -m -- "$HOME")" ]; then
  fail "OUT=$out is the home folder; give a folder of the run's own"
fi
case "$abs_repo/" in
  "$abs_out"/*) fail "OUT=$out is the repository or holds it; give a folder of the run's own" ;;
esac
if [ -e "$out" ] && ! [ -d "$out" ]; then fail "OUT=$out exists and is not a folder"; fi

[ -z "$frames" ] || [[ "$frames" =~ ^[0-9]+(-[0-9]+(x[1-9][0-9]*)?)?$ ]] ||
  fail "FRAMES=$frames: give FIRST-LAST, FIRST-LASTxSTEP or one frame (0-95, 0-95x2, 7), or nothing for the scene's animation"
[[ "$size" =~ ^[1-9][0-9]*x[1-9][0-9]*$ ]] || fail "SIZE=$size: give WIDTHxHEIGHT (352x240)"
[[ "$fps" =~ ^[0-9]*\.?[0-9]+$ ]] && [[ "$fps" =~ [1-9] ]] ||
  fail "FPS=$fps: give a positive number of frames a second (24)"
case $quality in
  draft | default | final) ;;
  *) fail "QUALITY=$quality: give draft, default or final" ;;
esac
