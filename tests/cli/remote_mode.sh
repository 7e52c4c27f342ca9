#!/usr/bin/env bash
# Runs a CLI test script (cli_test.sh, geometry_cli_test.sh, render_cli_test.sh) in remote mode:
# starts geodexd on 127.0.0.1 (a port it picks, no metrics port), sets GEODEX_SERVER so that every
# `geodex` command in the script goes through it, and GEODEX_MODE=remote so that the few checks of
# local-only flags (--method dijkstra, --max-windows, --threads, info --strict) are skipped.
# The script's own checks are the same in both modes. Bounded: every wait gives up.
# Usage: remote_mode.sh SCRIPT. Env: GEODEX, GEODEXD, DATA.
set -u
script="$1"
tmp=$(mktemp -d)
"$GEODEXD" --listen 127.0.0.1:0 --data-dir "$tmp/data" --metrics_listen "" --pool-threads 2 \
  --shutdown_grace_seconds 5 >"$tmp/server.log" 2>&1 &
pid=$!
cleanup() {
  kill -TERM "$pid" 2>/dev/null
  for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$pid" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
port=""
for _ in $(seq 1 300); do
  port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$tmp/server.log" | head -1)
  [ -n "$port" ] && break
  sleep 0.1
done
if [ -z "$port" ]; then
  echo "FAIL: geodexd did not start"; cat "$tmp/server.log"; exit 1
fi
GEODEX_SERVER="127.0.0.1:$port" GEODEX_MODE=remote bash "$script"
