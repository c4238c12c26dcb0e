#!/usr/bin/env bash
# Seed corpora for the fuzz harnesses, one folder per reader under OUT:
#   gltf/            the committed scenes (tests/data/external, pipelines/scenes/cornell-moving)
#   container/ link_hierarchy/ key_window/ intervals/ texture_movie/ frame/
#                    rad-global (also two --window runs), rad-intervals, rad-movies and rad-compose run on the bundled
#                    cornell-moving scene at a tiny size (frames 0-2, 44x30, --eps 0.05: a
#                    23 KB global.rlh instead of 1.2 MB, so each execution stays fast), so
#                    nothing binary is committed and the seeds are always the current version.
# The committed regressions (tests/data/fuzz-regressions) are not seeds: the normal build
# replays them, and some (huge declared sizes) take ASan tens of seconds each.
# Usage: tests/fuzz/make_seeds.sh BIN_DIR OUT
set -euo pipefail
trap '[ $? -eq 0 ] || cat "$out/pipeline/tools.log" 2>/dev/null' EXIT
bin=$1
out=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
scene=$src/pipelines/scenes/cornell-moving.gltf
work=$out/pipeline
rm -rf "$out"
mkdir -p "$out"/{gltf,container,link_hierarchy,key_window,intervals,texture_movie,frame} "$work"

find "$src/tests/data/external" -name '*.gltf' -o -name '*.glb' | while read -r f; do
  cp "$f" "$out/gltf/"
done
cp "$scene" "$out/gltf/"

log=$work/tools.log
"$bin/rad-global" "$scene" -o "$work/global.rlh" --frames 0-2 --eps 0.05 >"$log" 2>&1
for window in 0-1 2-2; do
  "$bin/rad-global" "$scene" -o "$work/w$window.rkw" --frames 0-2 --key-step 1 --eps 0.05 \
    --window "$window" >>"$log" 2>&1
done
"$bin/rad-intervals" "$scene" -o "$work/intervals.rti" --frames 0-2 --size 44x30 >>"$log" 2>&1
"$bin/rad-movies" "$scene" "$work/global.rlh" "$work/intervals.rti" -o "$work/movies" >>"$log" 2>&1
"$bin/rad-compose" "$scene" "$work/global.rlh" "$work/intervals.rti" "$work/movies" \
  -o "$work/frames" --size 44x30 >>"$log" 2>&1

cp "$work/global.rlh" "$work/intervals.rti" "$out/container/"
cp "$work/global.rlh" "$out/link_hierarchy/"
cp "$work"/w*.rkw "$out/key_window/"
cp "$work/w0-1.rkw" "$out/container/"
cp "$work/intervals.rti" "$out/intervals/"
# A handful of movies (constant and keyed ones) is enough variety; the smallest first.
ls -S -r "$work"/movies/*.exr | head -n 8 | xargs -I{} cp {} "$out/texture_movie/"
cp "$work"/frames/*.exr "$out/frame/"

for reader in gltf container link_hierarchy key_window intervals texture_movie frame; do
  echo "fuzz seeds: $reader: $(ls "$out/$reader" | wc -l) files, $(du -sk "$out/$reader" | cut -f1) KB"
done
