#!/usr/bin/env bash
# `cmake --install` (issue 55): the tools, the Makefiles, their scripts and the bundled scene
# land under a temporary prefix, and the installed animation.mk prints its stage commands from
# another folder, with BIN given and with BIN's default (share/rad/build/bin, a link to bin).
# Usage: install_test.sh CMAKE BUILD_DIR SCRATCH
set -euo pipefail
cmake=$1 build=$2 scratch=$3
rm -rf "$scratch"
mkdir -p "$scratch"
prefix=$scratch/prefix
"$cmake" --install "$build" --prefix "$prefix" >"$scratch/install.log"
fail() { echo "install_test: $*" >&2; exit 1; }

for tool in rad-global rad-intervals rad-movies rad-compose rad-reference rad-inspect rad-diff; do
  [ -x "$prefix/bin/$tool" ] || fail "$prefix/bin/$tool missing or not executable"
done
share=$prefix/share/rad
for f in animation.mk stages.mk slurm.mk scenes/cornell-moving.gltf; do
  [ -f "$share/pipelines/$f" ] || fail "$share/pipelines/$f missing"
done
for f in check-variables.sh clean.sh encode.sh slurm-task.sh bench.py; do
  [ -x "$share/pipelines/$f" ] || fail "$share/pipelines/$f missing or not executable"
done
[ "$(readlink -f "$share/build/bin")" = "$(readlink -f "$prefix/bin")" ] ||
  fail "$share/build/bin does not lead to $prefix/bin"

# From another folder, as a user of the installed tree runs it.
cd "$scratch"
mk=$share/pipelines/animation.mk
for bin in "$prefix/bin" ""; do
  out=$(make -s -f "$mk" ${bin:+BIN="$bin"} OUT="$scratch/out" FRAMES=0-7 SIZE=88x60 \
    stage-commands) || fail "stage-commands failed (BIN=${bin:-default})"
  expected_bin=${bin:-$share/build/bin}
  for stage in global intervals movies compose; do
    grep -q "^$stage	$expected_bin/rad-$stage $share/pipelines/scenes/cornell-moving.gltf " \
      <<<"$out" || fail "no $stage command from $expected_bin (BIN=${bin:-default}): $out"
  done
done
# The default BIN finds the tools: the scene is read (rad-inspect --inputs) without an error.
make -s -n -f "$mk" OUT="$scratch/out" FRAMES=0-7 SIZE=88x60 >/dev/null ||
  fail "make -n with the default BIN failed"
rm -rf "$scratch"
echo "install_test: ok"
