#!/usr/bin/env bash
# docs/terrain.md's terrain-through-geodexd example (scripts/terrain_service_example.sh and
# scripts/terrain_example.py) runs as written against a geodexd of its own (127.0.0.1, a port it
# picks, no metrics port) and makes what it says. Bounded: every wait gives up.
# Env: GEODEX, GEODEXD, EXAMPLE (the script), GEODEX_PYTHON_STUBS (build/python).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
start_geodexd "$tmp/server.log" --pool-threads 2 --shutdown_grace_seconds 5 ||
  die "geodexd did not start" "$tmp/server.log"
GEODEX="$GEODEX" timeout 300 bash "$EXAMPLE" "127.0.0.1:$geodexd_port" "$tmp/out" \
  >"$tmp/log.txt" 2>&1 || die "the example" "$tmp/log.txt"
/usr/bin/python3 - "$tmp" <<'PY' || die "the example's outputs" "$tmp/log.txt"
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
