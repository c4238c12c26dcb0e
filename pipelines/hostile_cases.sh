#!/usr/bin/env bash
# Issue 54's hostile cases, run as a user would, printed as a Markdown table: case | exit | first
# line of stderr | seconds | peak MiB. Each case also has a test (tests/pipeline, tests/cli,
# tests/format); this script is the closing note's table, reproducible.
#
#   pipelines/hostile_cases.sh [BIN] [WORK]     (defaults: build/bin, /tmp/rad-hostile)
set -uo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${1:-build/bin}")
work=${2:-/tmp/rad-hostile}
rm -rf "$work"
mkdir -p "$work"
scene=pipelines/scenes/cornell-moving.gltf
make_=(make --no-print-directory -f pipelines/animation.mk "BIN=$bin" FRAMES=0-7 SIZE=88x60)

echo "| case | exit | first line of stderr | s | peak MiB |"
echo "|---|---|---|---|---|"
# run NAME COMMAND...: one row (a command that does not end in 20 s is a hang).
run() {
  local name=$1
  shift
  local t0 t1 rc line
  t0=$(date +%s.%N)
  timeout 20 /usr/bin/time -f '%M' -o "$work/rss" "$@" >/dev/null 2>"$work/err"
  rc=$?
  t1=$(date +%s.%N)
  [ "$rc" = 124 ] && rc="124 (hang)"
  line=$(grep -v '^Command exited with' "$work/err" | head -1 | cut -c1-150)
  printf '| %s | %s | `%s` | %.2f | %d |\n' "$name" "$rc" "${line//|/\\|}" \
    "$(awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }')" "$(($(tail -1 "$work/rss" 2>/dev/null || echo 0) / 1024))"
}

# The bundled scene with its buffer in an external .bin and an image, in DIR; TEXTURE is the
# image's URI, used as the base colour of material 0 (texcoords from positions).
external_scene() {
  local dir=$1 texture=$2
  mkdir -p "$dir"
  python3 - "$scene" "$dir" "$texture" <<'EOF'
import base64, json, struct, sys
src, dst, uri = sys.argv[1:4]
j = json.load(open(src))
data = bytearray(base64.b64decode(j["buffers"][0]["uri"].split(",", 1)[1]))
# TEXCOORD_0 for every primitive: (x, z) of each vertex, appended to the buffer.
for mesh in j["meshes"]:
    for p in mesh["primitives"]:
        acc = j["accessors"][p["attributes"]["POSITION"]]
        view = j["bufferViews"][acc["bufferView"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        stride = view.get("byteStride", 12)
        uv = bytearray()
        for i in range(acc["count"]):
            x, y, z = struct.unpack_from("<3f", data, start + i * stride)
            uv += struct.pack("<2f", x, z)
        while len(data) % 4:
            data.append(0)
        j["bufferViews"].append({"buffer": 0, "byteOffset": len(data), "byteLength": len(uv)})
        data += uv
        j["accessors"].append({"bufferView": len(j["bufferViews"]) - 1, "componentType": 5126,
                               "count": acc["count"], "type": "VEC2"})
        p["attributes"]["TEXCOORD_0"] = len(j["accessors"]) - 1
open(dst + "/scene.bin", "wb").write(data)
j["buffers"][0] = {"uri": "scene.bin", "byteLength": len(data)}
j["images"] = [{"uri": uri}]
j["textures"] = [{"source": 0}]
j["materials"][0].setdefault("pbrMetallicRoughness", {})["baseColorTexture"] = {"index": 0}
json.dump(j, open(dst + "/scene.gltf", "w"))
EOF
}

# 1. Paths.
mkdir -p "$work/renders" "$work/v2"
run 'clean OUT="W/renders W/v2"' "${make_[@]}" clean "OUT=$work/renders $work/v2"
run 'OUT=/' "${make_[@]}" OUT=/
run "OUT='x;touch y'" "${make_[@]}" "OUT=$work/x;touch $work/y"
run 'OUT= (empty)' "${make_[@]}" OUT=
run 'OUT=$HOME' "${make_[@]}" "OUT=$HOME"
run 'OUT a regular file' "${make_[@]}" "OUT=$0"
run 'SCENE=-scene.gltf' bash -c "cp $scene $work/-scene.gltf && cd $work && make -s -f $PWD/pipelines/animation.mk BIN=$bin SCENE=-scene.gltf OUT=dash FRAMES=0-7 SIZE=88x60"
[ -d "$work/renders" ] && [ -d "$work/v2" ] && [ ! -e "$work/y" ] &&
  echo "| (after the above: renders/ and v2/ still there, no y) | | | | |"

# 2. Every input is a dependency.
external_scene "$work/ext" wall.png
cp pipelines/scenes/cornell-moving-contact-sheet.png "$work/ext/wall.png"
ext=("${make_[@]}" "SCENE=$work/ext/scene.gltf" "OUT=$work/ext/out")
run 'external .bin and image: first run' "${ext[@]}"
printf '\x42' | dd of="$work/ext/scene.bin" bs=1 seek=40 conv=notrunc status=none
run '.bin changed: make -n (stages it would run)' bash -c "${ext[*]} -n | grep -cE '/rad-(global|intervals|movies|compose) ' >&2"
run '.bin changed: make' "${ext[@]}"

# 3. A stamp that cannot be written (OUT on a tmpfs remounted read-only: root ignores modes).
mkdir -p "$work/ro"
if mount -t tmpfs -o size=64m none "$work/ro" 2>/dev/null; then
  "${make_[@]}" "OUT=$work/ro/out" >/dev/null 2>&1
  mount -o remount,ro "$work/ro"
  run 'read-only OUT, COMPOSE_FLAGS="--exposure 2"' "${make_[@]}" "OUT=$work/ro/out" COMPOSE_FLAGS="--exposure 2"
  run 'read-only OUT, FRAMES=0-3' "${make_[@]}" "OUT=$work/ro/out" FRAMES=0-3
  run 'read-only fresh OUT' "${make_[@]}" "OUT=$work/ro/fresh"
  umount "$work/ro"
fi

# 4. Textures that cannot be read.
for t in missing.png /dev/zero http://example.com/t.png file:///etc/passwd; do
  external_scene "$work/t" "$t"
  run "texture $t: rad-global" "$bin/rad-global" "$work/t/scene.gltf" -o "$work/t/g.rlh" --frames 0-1
done
external_scene "$work/t" zero.png
ln -sf /dev/zero "$work/t/zero.png"
run 'texture a link to /dev/zero: rad-global' "$bin/rad-global" "$work/t/scene.gltf" -o "$work/t/g.rlh" --frames 0-1
external_scene "$work/t" trunc.jpg
ffmpeg -loglevel error -y -f lavfi -i color=c=red:s=64x64 -frames:v 1 "$work/t/full.jpg"
head -c $(($(stat -c %s "$work/t/full.jpg") / 2)) "$work/t/full.jpg" >"$work/t/trunc.jpg"
run 'texture a truncated JPEG: rad-global' "$bin/rad-global" "$work/t/scene.gltf" -o "$work/t/g.rlh" --frames 0-1

# 5. Hangs and unbounded reads.
mkfifo "$work/fifo.gltf"
run 'a FIFO as SCENE: rad-global' "$bin/rad-global" "$work/fifo.gltf" -o "$work/g.rlh"
run 'a FIFO as SCENE: make' "${make_[@]}" "SCENE=$work/fifo.gltf" "OUT=$work/fifo-out"
external_scene "$work/f" wall.png
rm -f "$work/f/scene.bin" && mkfifo "$work/f/scene.bin"
run 'a FIFO as .bin: rad-global' "$bin/rad-global" "$work/f/scene.gltf" -o "$work/g.rlh"
external_scene "$work/f2" fifo.png
mkfifo "$work/f2/fifo.png"
run 'a FIFO as texture: rad-global' "$bin/rad-global" "$work/f2/scene.gltf" -o "$work/g.rlh" --frames 0-1
run 'rad-global /dev/zero' "$bin/rad-global" /dev/zero -o "$work/g.rlh"
mkdir -p "$work/dir.gltf"
run 'a directory as SCENE' "$bin/rad-global" "$work/dir.gltf" -o "$work/g.rlh"
external_scene "$work/d" imgdir
mkdir -p "$work/d/imgdir"
run 'an image URI that is a folder' "$bin/rad-global" "$work/d/scene.gltf" -o "$work/g.rlh" --frames 0-1

# 6. A 12,000 x 12,000 PNG (a few hundred KB).
external_scene "$work/big" big.png
ffmpeg -loglevel error -y -f lavfi -i color=c=gray:s=12000x12000 -frames:v 1 "$work/big/big.png"
for s in rad-global rad-intervals; do
  run "12000² texture: $s" "$bin/$s" "$work/big/scene.gltf" -o "$work/big/$s.out" --frames 0-1
done

# 7. Resource limits.
run 'rad-global --threads 100000000' "$bin/rad-global" "$scene" -o "$work/g.rlh" --threads 100000000
run 'rad-movies --threads 100000000' "$bin/rad-movies" "$scene" a b -o "$work/m" --threads 100000000
"$bin/rad-global" "$scene" -o "$work/g.rlh" --frames 0-7 >/dev/null 2>&1
for mb in 300 450 600; do
  run "rad-intervals under ulimit -v ${mb} MB" bash -c "ulimit -v $((mb * 1024)); exec $bin/rad-intervals $scene -o $work/i.rti --frames 0-7 --size 88x60"
done

# 8. Intermediates from a scene with other materials.
python3 - "$scene" "$work/recoloured.gltf" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
j["materials"][0].setdefault("pbrMetallicRoughness", {})["baseColorFactor"] = [0.2, 0.9, 0.2, 1]
json.dump(j, open(sys.argv[2], "w"))
EOF
"$bin/rad-intervals" "$scene" -o "$work/i.rti" --frames 0-7 --size 88x60 >/dev/null 2>&1
run 'rad-movies, global.rlh of other materials' "$bin/rad-movies" "$work/recoloured.gltf" "$work/g.rlh" "$work/i.rti" -o "$work/m2"

# 9. Stepped ranges and odd sizes.
run 'FRAMES=0-15x2 SIZE=87x59' "${make_[@]}" "OUT=$work/step" FRAMES=0-15x2 SIZE=87x59
echo "| (the mp4: $(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames,width,height -of csv=p=0 "$work/step/movie.mp4") = width,height,frames) | | | | |"

# 11. Messages.
cat >"$work/yfov.py" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
for c in j["cameras"]:
    c["perspective"]["yfov"] = 1e-9
json.dump(j, open(sys.argv[2], "w"))
EOF
python3 "$work/yfov.py" "$scene" "$work/yfov.gltf"
run 'yfov 1e-9: rad-intervals' "$bin/rad-intervals" "$work/yfov.gltf" -o "$work/i2.rti" --frames 0-1 --size 88x60
run 'make_paper_scenes.py --help' bash -c "cd $work && python3 $PWD/pipelines/scenes/make_paper_scenes.py --help >/dev/null; ls -d -- --help 2>/dev/null >&2; exit 0"
