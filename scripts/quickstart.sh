#!/usr/bin/env bash
# README's first command: install the dependencies (as root), build geodexd and the geodex CLI,
# start geodexd on 127.0.0.1 with its built-in sample meshes, and answer a first query through it.
# The server keeps running afterwards (its PID and how to stop it are printed at the end).
# Env: GEODEX_PORT (default 50051), GEODEX_HTTP_PORT (default 8080: the HTTP/JSON API),
# GEODEX_DATA_DIR (default build/geodex-data).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" -eq 0 ]; then
  bash scripts/install-deps.sh
else
  echo "quickstart: not root, skipping apt-get (run scripts/install-deps.sh as root if the build fails)"
fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
ninja -C build geodex geodexd
port="${GEODEX_PORT:-50051}"
data="${GEODEX_DATA_DIR:-build/geodex-data}"
server="127.0.0.1:$port"
http="127.0.0.1:${GEODEX_HTTP_PORT:-8080}"
if ./build/client/geodex --server "$server" health >/dev/null 2>&1; then
  echo "--- a geodexd already answers on $server; using it"
else
  echo "--- starting geodexd on $server (data in $data, log in build/geodexd.log)"
  nohup ./build/server/geodexd --listen "$server" --http_listen "$http" --data-dir "$data" \
    >build/geodexd.log 2>&1 &
  pid=$!
  for _ in $(seq 1 100); do  # up to 20 s
    ./build/client/geodex --server "$server" health >/dev/null 2>&1 && break
    kill -0 "$pid" 2>/dev/null || { cat build/geodexd.log; exit 1; }
    sleep 0.2
  done
fi
echo "--- geodex --server $server health"
./build/client/geodex --server "$server" health
echo "--- geodex --server $server mesh list"
./build/client/geodex --server "$server" mesh list
echo "--- geodex --server $server path terrain --from 0 --to 4224   (length, then the first points)"
path_text=$(./build/client/geodex --server "$server" path terrain --from 0 --to 4224)
printf '%s\n' "$path_text" | head -n 4
if curl -sf "http://$http/v1/meshes?pageSize=1" >/dev/null 2>&1; then
  echo "--- the same path over HTTP/JSON: curl -X POST http://$http/v1/meshes/terrain:findShortestPath"
  # (Into a variable first: `curl | head` could fail curl on a closed pipe, and pipefail is on.)
  http_answer=$(curl -sf -X POST -H 'Content-Type: application/json' \
    "http://$http/v1/meshes/terrain:findShortestPath" -d '{"from": {"vertex": 0}, "to": {"vertex": 4224}}')
  printf '%s' "${http_answer:0:120}"
  echo " ..."
  echo "--- HTTP/JSON API on http://$http/v1/meshes (docs/service.md, \"HTTP/JSON\")"
fi
if [ -n "${pid:-}" ]; then
  echo "--- geodexd keeps running (pid $pid); stop it with: kill $pid"
fi
