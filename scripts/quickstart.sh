#!/usr/bin/env bash
# README's first command: install dependencies (as root), build the CLI, and answer a first query
# on a built-in sample mesh. (The gRPC service will take over this role once it exists.)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" -eq 0 ]; then
  bash scripts/install-deps.sh
else
  echo "quickstart: not root, skipping apt-get (run scripts/install-deps.sh as root if the build fails)"
fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
ninja -C build geodex
echo "--- geodex info sample:terrain"
./build/client/geodex info sample:terrain
echo "--- geodex distances sample:terrain --sources 0,4224 --stats (last 3 of 4225 distances)"
./build/client/geodex distances sample:terrain --sources 0,4224 --stats | tail -n 3
