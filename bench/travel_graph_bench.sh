#!/usr/bin/env bash
# Travel paths through geodexd with and without its shared travel graphs: two geodexd on 127.0.0.1
# (ports they pick), one with the result cache (where the graphs live, the default budget) and one
# with --result_cache_bytes 0, then farm-bench times the same Python client run against each: it
# uploads a DEM (idempotent) and asks CALLS travel paths at a constant speed, optionally with
# friction polygons, each from a seeded random cell to one up to 12 cells away (a planner's local
# goals: a long path's search costs far more than the graph, so sharing it gains little there).
# POINTS=map (environment) takes each end as a map point a fraction of a cell off the vertex (inside
# a face, as a GIS user's clicks are): without friction (one weight) the exact engine's cached
# surface serves those too; with friction each query builds a graph refined around them.
# One benchmark at a time.
#
# Usage: [POINTS=vertices|map] bench/travel_graph_bench.sh DEM.tif [DEM_STEP] [FRICTION.geojson]
#        [CALLS] [PAIRS]
#   e.g. bench/travel_graph_bench.sh /tmp/jacksboro.tif 4 /tmp/friction.geojson 20 5
set -euo pipefail
cd "$(dirname "$0")/.."
dem="$1"
step="${2:-4}"
friction="${3:-}"
calls="${4:-20}"
pairs="${5:-5}"
points="${POINTS:-vertices}"
case "$points" in vertices | map) ;; *) echo "POINTS: vertices or map, not '$points'" >&2; exit 2 ;; esac
build="${BUILD_DIR:-build}"
tmp=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null; wait "$p" 2>/dev/null; done; rm -rf "$tmp"' EXIT
start() {  # start NAME FLAGS...: a geodexd, its PID kept for the exit trap; sets $port
  local name=$1
  shift
  "$build/server/geodexd" --listen 127.0.0.1:0 --metrics_listen "" --samples=false \
    --data-dir "$tmp/$name" "$@" >"$tmp/$name.log" 2>&1 &
  pids+=($!)
  port=""
  for _ in $(seq 300); do
    port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$tmp/$name.log")
    [ -n "$port" ] && break
    sleep 0.1
  done
  [ -n "$port" ] || { cat "$tmp/$name.log" >&2; exit 1; }
}
start cached  # (not in $(...): a subshell would keep the PID from the trap)
cached=$port
start uncached --result_cache_bytes 0
uncached=$port

cat >"$tmp/paths.py" <<'EOF'
import random, sys
import geodex
server, dem, step, friction, calls, points = sys.argv[1:7]
with geodex.GeodexClient(server) as c:
    mesh = c.upload(dem, dem_step=int(step))
    travel = geodex.Travel(speed_kmh=4, friction_geojson=open(friction).read() if friction else None)
    # A planner's local goals: from a random cell centre to one up to 12 cells (at the step)
    # away; a DEM's vertices run row by row (no nodata here).
    from osgeo import gdal
    ds = gdal.Open(dem)
    gt, s = ds.GetGeoTransform(), int(step)
    width = (ds.RasterXSize - 1) // s + 1
    r = random.Random(2010)
    def point(v):  # the vertex, or a map point 0.3 and 0.4 of a step east and south of it
        if points == "vertices":
            return geodex.vertex(v)
        col, row = v % width, v // width
        col, row = min(col, width - 2), min(row, mesh.vertex_count // width - 2)
        return geodex.map_point(gt[0] + ((col + 0.3) * s + 0.5) * gt[1],
                                gt[3] + ((row + 0.4) * s + 0.5) * gt[5])
    for _ in range(int(calls)):
        a = r.randrange(mesh.vertex_count)
        b = a + r.randint(-12, 12) + width * r.randint(-12, 12)
        b = min(max(b, 0), mesh.vertex_count - 1)
        c.shortest_path(mesh.name, point(a), point(b), travel=travel)
EOF
run() { echo "env PYTHONPATH=client/python:$build/python /usr/bin/python3 $tmp/paths.py 127.0.0.1:$1 $dem $step '$friction' $calls $points"; }
echo "commit $(git rev-parse --short HEAD); $calls travel paths per run (4 km/h, epsilon 0.01${friction:+, friction $friction}) between $points on $dem, step $step"
echo "A: result cache on (shared travel graphs); B: --result_cache_bytes 0"
# One run first, so that an error shows (farm-bench keeps only the exit codes).
bash -c "$(run "$cached")"
farm-bench -n "$pairs" --warmup 1 --timeout 600 --vs "$(run "$uncached")" -- bash -c "$(run "$cached")"
