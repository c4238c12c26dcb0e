#!/bin/bash
# formats/build_info.cmake: the revision a build reports. In a scratch git checkout: a clean
# tree gives HEAD's 12 hex digits, a tracked file changed gives them with "-dirty" (the
# benchmark binaries built before their commit had carried their parent's revision), and a tree
# that is not a checkout gives "unknown".
# Usage: build_info_revision_test.sh CMAKE GIT SCRIPT
set -u
CMAKE=$1 GIT=$2 SCRIPT=$3
dir=$(mktemp -d) || exit 1
trap 'rm -rf "$dir"' EXIT
revision() {  # the revision the generated source returns for source dir $1
  "$CMAKE" -DSOURCE_DIR="$1" -DGIT="$GIT" -DOUTPUT="$dir/out.cpp" -P "$SCRIPT" || return 1
  sed -n 's/.*return "\(.*\)";.*/\1/p' "$dir/out.cpp"
}
fail() { echo "build_info_revision_test: $*" >&2; exit 1; }
mkdir "$dir/src" "$dir/plain"
g() { "$GIT" -C "$dir/src" -c user.name=test -c user.email=test@example.org "$@" >/dev/null; }
g init -q && echo a > "$dir/src/f" && g add f && g commit -q -m one || fail "git setup"
head=$("$GIT" -C "$dir/src" rev-parse --short=12 HEAD)
[ "$(revision "$dir/src")" = "$head" ] || fail "clean tree: $(revision "$dir/src") != $head"
echo b > "$dir/src/f"
[ "$(revision "$dir/src")" = "$head-dirty" ] || fail "changed file: $(revision "$dir/src")"
g add f
[ "$(revision "$dir/src")" = "$head-dirty" ] || fail "staged change: $(revision "$dir/src")"
g commit -q -m two
head=$("$GIT" -C "$dir/src" rev-parse --short=12 HEAD)
[ "$(revision "$dir/src")" = "$head" ] || fail "committed: $(revision "$dir/src") != $head"
echo untracked > "$dir/src/new"
[ "$(revision "$dir/src")" = "$head" ] || fail "an untracked file made it dirty"
[ "$(revision "$dir/plain")" = "unknown" ] || fail "not a checkout: $(revision "$dir/plain")"
echo "build_info_revision_test: clean $head, dirty, unknown: ok"
