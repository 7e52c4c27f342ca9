#!/usr/bin/env bash
# README's terrain-through-geodexd example (scripts/terrain_service_example.sh and
# scripts/terrain_example.py) runs as written against a geodexd of its own (127.0.0.1, a port it
# picks, no metrics port) and makes what it says. Bounded: every wait gives up.
# Env: GEODEX, GEODEXD, EXAMPLE (the script), GEODEX_PYTHON_STUBS (build/python).
set -u
tmp=$(mktemp -d)
"$GEODEXD" --listen 127.0.0.1:0 --metrics_listen "" --pool-threads 2 --shutdown_grace_seconds 5 \
  >"$tmp/server.log" 2>&1 &
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
[ -n "$port" ] || { echo "FAIL: geodexd did not start"; cat "$tmp/server.log"; exit 1; }
GEODEX="$GEODEX" timeout 300 bash "$EXAMPLE" "127.0.0.1:$port" "$tmp/out" >"$tmp/log.txt" 2>&1 ||
  { cat "$tmp/log.txt"; echo "FAIL: the example"; exit 1; }
/usr/bin/python3 - "$tmp" <<'PY' || { cat "$tmp/log.txt"; echo "FAIL: the example's outputs"; exit 1; }
import json, math, sys
from shapely.geometry import shape
t = sys.argv[1]
log = open(f"{t}/log.txt").read().splitlines()
assert any("valley" in l and "vertices" in l for l in log), log
at = [l.split("\t") for l in log if "\texact " in l]  # the hut's distance, around the lake
assert len(at) == 1 and math.isfinite(float(at[0][2].split()[1])), log
assert "WGS 84 / UTM zone 32N" in log, log
iso = json.load(open(f"{t}/out/isochrones-py.geojson"))["features"]
assert [f["properties"]["level"] for f in iso] == [500, 1000]
assert all(shape(f["geometry"]).is_valid and shape(f["geometry"]).area > 0 for f in iso)
PY
echo "terrain service example: ok"
