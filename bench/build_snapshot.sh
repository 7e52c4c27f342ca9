#!/usr/bin/env bash
# Builds geodex_bench (Release, one job) from a clean `git archive` of a commit, so that benchmark
# numbers belong to exactly that commit while the working tree is being edited. Read-only for the
# repository (no checkout, stash or worktree).
#
#   bench/build_snapshot.sh [COMMIT] [--with-working-harness]
#
# COMMIT defaults to HEAD. --with-working-harness copies the harness files of the working tree
# (bench/ and testkit/, which has the CGAL wrapper) over the snapshot, for a harness that is not
# committed yet. Prints the path of the binary last.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
rev=HEAD
overlay=0
for arg in "$@"; do
  case "$arg" in
    --with-working-harness) overlay=1 ;;
    -*) echo "unknown option $arg" >&2; exit 2 ;;
    *) rev=$arg ;;
  esac
done
commit=$(git -C "$repo" rev-parse --short "$rev")
dir=${SNAPSHOT_DIR:-/tmp/geodex-bench-$commit}
rm -rf "$dir/src"
mkdir -p "$dir/src"
git -C "$repo" archive "$commit" | tar -x -C "$dir/src"
label=$commit
if [[ $overlay == 1 ]]; then
  for f in bench testkit; do
    mkdir -p "$dir/src/$(dirname "$f")"
    cp -r "$repo/$f" "$dir/src/$(dirname "$f")/"
  done
  label="$commit with the working tree's bench harness"
fi
cmake -S "$dir/src" -B "$dir/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGEODEX_BUILD_TESTS=OFF \
      -DGEODEX_BUILD_BENCH=ON "-DGEODEX_BENCH_COMMIT=$label" >/dev/null
ninja -C "$dir/build" -j1 geodex_bench >&2
echo "$dir/build/bench/geodex_bench"
