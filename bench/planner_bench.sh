#!/usr/bin/env bash
# A planner's workload (issue 56): a geodexd with default flags on 127.0.0.1 (a port it picks, no
# metrics port), then bench/planner_bench.py: 40 starts x 4 short paths per client at a 0.1 s
# timeout, from 1, 4 and 16 concurrent clients. Prints a Markdown table (docs/performance.md,
# "A planner's workload"). Bounded: the server is stopped by its PID at exit.
# Usage: bench/planner_bench.sh [BUILD_DIR] [GRID_N]
# Env: GEODEXD, another server binary to measure with this build's client (an older commit's).
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
n="${2:-211}"
tmp=$(mktemp -d)
"${GEODEXD:-$build/server/geodexd}" --listen 127.0.0.1:0 --metrics_listen "" --data-dir "$tmp/data" \
  >"$tmp/server.log" 2>&1 &
pid=$!
trap 'kill "$pid" 2>/dev/null; wait "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
port=""
for _ in $(seq 300); do
  port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$tmp/server.log")
  [ -n "$port" ] && break
  sleep 0.1
done
[ -n "$port" ] || { cat "$tmp/server.log"; exit 1; }
PYTHONPATH=client/python:"$build/python" /usr/bin/python3 bench/planner_bench.py \
  "127.0.0.1:$port" "$n"
