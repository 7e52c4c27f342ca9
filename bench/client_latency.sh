#!/usr/bin/env bash
# Client latency from C++ and Python (issue 34): a geodexd on 127.0.0.1 (a port it picks), then
# bench/client_latency.cc and .py in turn on armadillo and the Jacksboro terrain, one call at a time,
# one benchmark at a time. Prints a Markdown table (docs/performance.md, "Clients in a control loop").
# Usage: bench/client_latency.sh [BUILD_DIR] [CALLS_PER_GROUP]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
calls="${2:-50}"
meshes=(../shared/meshes/armadillo.off ../shared/meshes/jacksboro-terrain.off.gz)
tmp=$(mktemp -d)
"$build/server/geodexd" --listen 127.0.0.1:0 --metrics_listen "" --data-dir "$tmp/data" \
  --pool-threads 1 >"$tmp/server.log" 2>&1 &
pid=$!
trap 'kill "$pid" 2>/dev/null; wait "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
port=""
for _ in $(seq 300); do
  port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$tmp/server.log")
  [ -n "$port" ] && break
  sleep 0.1
done
[ -n "$port" ] || { cat "$tmp/server.log"; exit 1; }
echo "| client | mesh | targets | calls | p50 ms | p99 ms | queries/s | server solve p50 ms | p50 - solve ms |"
echo "|---|---|---|---:|---:|---:|---:|---:|---:|"
for mesh in "${meshes[@]}"; do
  [ -f "$mesh" ] || { echo "(missing $mesh)"; continue; }
  "$build/client/geodex" distances "$mesh" --sources 0 >"$tmp/distances.txt"  # locally
  "$build/bench/geodex_client_latency" "127.0.0.1:$port" "$mesh" "$tmp/distances.txt" "$calls"
  PYTHONPATH=client/python:"$build/python" /usr/bin/python3 bench/client_latency.py \
    "127.0.0.1:$port" "$mesh" "$tmp/distances.txt" "$calls"
done
