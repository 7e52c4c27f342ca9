#!/usr/bin/env bash
# Runs the whole test suite of a configured and built tree (default: build/). This is the test
# command of README.md, and what .ci/run calls.
set -euo pipefail
build_dir="${1:-build}"
cd "$(dirname "$0")/.."
if [ ! -f "$build_dir/CTestTestfile.cmake" ]; then
  bash scripts/install-deps.sh 2>/dev/null || true
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
ninja -C "$build_dir"
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" --timeout 600
