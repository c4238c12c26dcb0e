#!/usr/bin/env bash
# first_render_bare.sh ROOT [REPO]: times the README's first command on a bare Debian 12 machine,
# apt included. ROOT becomes a debootstrap'd Debian 12 (minbase plus git, g++, cmake, make and
# ca-certificates: what a new machine of this project's kind has); REPO (default: this clone) is
# cloned into it and `pipelines/bootstrap.sh && make -f pipelines/animation.mk` runs there in a
# chroot, from an empty package set to frames and mp4. Needs root, debootstrap and Debian's
# package registry. Prints the exit status and wall seconds; the log is ROOT/root/first-render.log.
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 ROOT [REPO]" >&2; exit 2; }
root=$(realpath -m "$1")
repo=$(realpath "${2:-$(dirname "$0")/..}")
mirror=http://deb.debian.org/debian
if [ ! -x "$root/usr/bin/g++" ]; then
  debootstrap --variant=minbase --include=git,g++,cmake,make,ca-certificates bookworm "$root" \
    "$mirror" >"$root.debootstrap.log" 2>&1
fi
cp /etc/resolv.conf "$root/etc/resolv.conf"
printf 'deb %s bookworm main\ndeb %s bookworm-updates main\ndeb %s-security bookworm-security main\n' \
  "$mirror" "$mirror" "$mirror" >"$root/etc/apt/sources.list"
cleanup() {
  umount "$root/src" 2>/dev/null || true
  umount -R "$root/dev" 2>/dev/null || true
  umount "$root/proc" 2>/dev/null || true
}
trap cleanup EXIT
mountpoint -q "$root/proc" || mount -t proc proc "$root/proc"
mountpoint -q "$root/dev" || mount --rbind /dev "$root/dev"
mkdir -p "$root/src"
mountpoint -q "$root/src" || mount --bind "$repo" "$root/src"
rm -rf "$root/root/rad"
chroot "$root" bash -c '
  cd /root && git clone -q /src rad && cd rad
  start=$(date +%s%N)
  rc=0; (pipelines/bootstrap.sh && make -f pipelines/animation.mk) >/root/first-render.log 2>&1 || rc=$?
  end=$(date +%s%N)
  echo "exit $rc, $(( (end - start) / 1000000000 )) s wall; frames: $(ls out/cornell-moving/frames | wc -l) files; test binaries: $(find build -name "*_test" -type f | wc -l)"'
