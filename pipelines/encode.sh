#!/usr/bin/env bash
# The mp4 or the contact sheet of the frames rad-compose wrote (stages.mk's MP4_CMD and
# CONTACT_CMD), from exactly the frames FRAMES names: a stepped range (0-95x2) gives every one
# of its frames, in order (ffmpeg's own %04d reader stops at the first gap). A frame that is
# missing is an error, not a shorter movie. Odd sizes are padded by one black column or row
# (H.264 in yuv420p needs even sides). The output is written to a name of this process's own and
# moved into place; on SIGINT or SIGTERM ffmpeg is stopped and that file removed.
#
#   pipelines/encode.sh mp4|contact|segment FRAMES_DIR FRAMES FPS OUTPUT
#   pipelines/encode.sh concat FRAMES_DIR CHUNK,CHUNK,... FPS OUTPUT
#
# A render farm (slurm.mk, issue 58) encodes the mp4 in pieces: each compose task encodes its
# chunk of frames as a segment (`segment`: the mp4's encoder settings, into
# FRAMES_DIR/segment-FIRST-LAST.mp4), and `concat` joins the chunks' segments, in the order
# given, without re-encoding (ffmpeg's concat demuxer, -c copy), so that no task encodes every
# frame. Its mp4 holds the same frames as the single encode's, not the same bytes (each segment
# starts with a key frame). The contact sheet decodes only the eight frames it shows.
set -euo pipefail
kind=$1 dir=$2 frames=$3 fps=$4 output=$5

if [ "$kind" = concat ]; then
  exec 9>"$(dirname -- "$dir")/.frames.lock"
  flock -s 9
  list="$output.list.$$"
  tmp="$output.tmp.$$"
  trap 'rm -f -- "$list" "$tmp"' EXIT
  : >"$list"
  for chunk in ${frames//,/ }; do
    segment=$dir/segment-$chunk.mp4
    if ! [ -f "$segment" ]; then
      echo "encode.sh: $segment: missing (chunks $frames)" >&2
      exit 1
    fi
    # The concat demuxer's list syntax: one quoted path a line (' written as '\'').
    printf "file '%s'\n" "$(realpath -- "$segment" | sed "s/'/'\\\\''/g")" >>"$list"
  done
  ffmpeg -nostdin -loglevel error -y -f concat -safe 0 -i "$list" -c copy -f mp4 "$tmp"
  mv -f -- "$tmp" "$output"
  exit 0
fi

first=${frames%%-*}
last=$first step=1
if [[ $frames == *-* ]]; then
  last=${frames#*-}
  if [[ $last == *x* ]]; then step=${last#*x} last=${last%x*}; fi
fi

# The frames are listed and read under a shared lock on them (animation.mk: another run into the
# same OUT empties frames/ only under the exclusive one).
exec 9>"$(dirname -- "$dir")/.frames.lock"
flock -s 9

names=()
for ((f = first; f <= last; f += step)); do
  name=$(printf '%s/%04d.png' "$dir" "$f")
  if ! [ -f "$name" ]; then
    echo "encode.sh: $name: missing (FRAMES=$frames)" >&2
    exit 1
  fi
  names+=("$name")
done

tmp="$output.tmp.$$"
ffmpeg_pid=
cleanup() {
  if [ -n "$ffmpeg_pid" ]; then kill "$ffmpeg_pid" 2>/dev/null || true; fi
  rm -f -- "$tmp"
}
trap 'cleanup; trap - INT; kill -INT $$' INT
trap 'cleanup; trap - TERM; kill -TERM $$' TERM
trap 'rm -f -- "$tmp"' EXIT

even='pad=ceil(iw/2)*2:ceil(ih/2)*2'
case $kind in
  mp4 | segment)
    filter=$even
    args=(-c:v libx264 -pix_fmt yuv420p -crf 18 -f mp4) ;;
  contact)
    # Eight frames evenly spaced over the run, four across: every 12th of 96. Only those are
    # decoded (the sheet of ffmpeg's select=not(mod(n,every)) over every frame, byte for byte).
    every=$(((${#names[@]} + 7) / 8))
    shown=()
    for ((i = 0; i < ${#names[@]}; i += every)); do shown+=("${names[i]}"); done
    names=("${shown[@]}")
    filter="tile=4x2:padding=4:color=white"
    args=(-frames:v 1 -update 1 -f image2 -c:v png) ;;
  *) echo "encode.sh: unknown kind $kind" >&2; exit 2 ;;
esac

# The frames go through a pipe in the order FRAMES names them, so nothing depends on how a
# shell or ffmpeg would sort or glob their names.
cat -- "${names[@]}" |
  ffmpeg -nostdin -loglevel error -y -f image2pipe -c:v png -framerate "$fps" -i - \
    -vf "$filter" "${args[@]}" "$tmp" &
ffmpeg_pid=$!
wait "$ffmpeg_pid"
ffmpeg_pid=
mv -f -- "$tmp" "$output"
