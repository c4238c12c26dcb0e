#!/usr/bin/env bash
# Removes what the pipeline wrote into OUT, by name, and nothing else (issue 54): `make clean`
# runs it for the whole folder, the movies and frames rules (and slurm-pieces.sh) for the folder
# they are about to refill. A file the pipeline did not write is left where it is, and the folder
# that holds it is kept and named on stderr.
#
#   pipelines/clean.sh OUT [all|movies|frames|global-windows|interval-windows]...
#
# OUT has been checked by check-variables.sh (stages.mk) before this runs.
set -euo pipefail
out=$1
shift
parts=("${@:-all}")

# Files of FOLDER whose names match the extended regex PATTERN (the whole name), removed.
remove_matching() {
  local folder=$1 pattern=$2 f
  [ -d "$folder" ] || return 0
  for f in "$folder"/* "$folder"/.[!.]*; do
    [ -e "$f" ] || [ -L "$f" ] || continue
    if [[ ${f##*/} =~ ^($pattern)$ ]] && ! [ -d "$f" ]; then rm -f -- "$f"; fi
  done
}

# FOLDER removed if the pipeline's files were all it held; otherwise kept, and said so.
remove_folder() {
  local folder=$1
  [ -d "$folder" ] || return 0
  if ! rmdir -- "$folder" 2>/dev/null; then
    echo "clean: kept $folder: it holds files the pipeline did not write:" \
      "$(cd -- "$folder" && ls -A | head -5 | tr '\n' ' ')" >&2
  fi
}

# The temporary names the tools (formats/atomic_file.cpp: .NAME.tmp.PID.N.EXT) and the rules
# (NAME.tmp.PID) write beside their outputs.
temporaries='\..+\.tmp\.[0-9]+\.[0-9]+(\.[A-Za-z0-9]+)?|.+\.tmp\.[0-9]+'

clean_part() {
  case $1 in
    movies)
      remove_matching "$out/movies" "[0-9]{6}(\.piece-[0-9]{4})?\.exr|[0-9]{6}\.merge-lock|\.done|\.(p?shard[0-9a-z]*)-[0-9]+-of-[0-9]+|$temporaries"
      remove_folder "$out/movies" ;;
    frames)
      remove_matching "$out/frames" "[0-9]+\.(exr|png)|segment-[0-9]+-[0-9]+\.mp4|\.done|\.chunk-[0-9]+-of-[0-9]+|$temporaries"
      remove_folder "$out/frames" ;;
    global-windows)
      remove_matching "$out/global-windows" "w[0-9]+\.rkw|w[0-9]+-report\.json|\.window-[0-9]+-of-[0-9]+|\.merge-lock|$temporaries"
      remove_folder "$out/global-windows" ;;
    interval-windows)
      remove_matching "$out/interval-windows" "w[0-9]+\.rvs|\.window-[0-9]+-of-[0-9]+|\.merge-lock|$temporaries"
      remove_folder "$out/interval-windows" ;;
    logs)
      remove_matching "$out/logs" "[a-z-]+_[0-9]+\.(log|exit)(\.tmp)?"
      remove_folder "$out/logs" ;;
    all)
      for p in movies frames global-windows interval-windows logs; do clean_part "$p"; done
      remove_matching "$out/piece-costs" "[0-9]+-[0-9]+\.json"
      remove_folder "$out/piece-costs"
      remove_matching "$out" "global\.rlh|intervals\.rti|scene\.json|\.(movies|frames)\.lock|movie\.mp4|contact-sheet\.png|slurm-jobs|(scene|global|intervals|movies|compose)\.params|(global|intervals|movies|compose)-report(-[0-9x-]+|-[0-9]+of[0-9]+)?\.json|$temporaries"
      remove_folder "$out" ;;
    *) echo "clean.sh: unknown part $1" >&2; exit 2 ;;
  esac
}

for p in "${parts[@]}"; do clean_part "$p"; done
