#!/usr/bin/env bash
# README's terrain example (scripts/terrain_example.sh) runs as written and makes what it says:
# valid isochrone polygons, rasters aligned with the DEM, the walk around the lake, a picture.
# Env: GEODEX, EXAMPLE (the script).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
GEODEX="$GEODEX" bash "$EXAMPLE" "$tmp" >"$tmp/log.txt" 2>&1 || die "the example" "$tmp/log.txt"
/usr/bin/python3 - "$tmp" <<'PY' || die "the example's outputs"
import json, sys
from osgeo import gdal
from shapely.geometry import shape
t = sys.argv[1]
iso = json.load(open(f"{t}/isochrones.geojson"))["features"]
assert [f["properties"]["level"] for f in iso] == [500, 1000, 2000, 3000]
areas = [shape(f["geometry"]).area for f in iso]
assert all(shape(f["geometry"]).is_valid for f in iso) and areas == sorted(areas) and areas[0] > 0
dem, dist, near = (gdal.Open(f"{t}/{n}.tif") for n in ("valley", "distance", "nearest"))
assert dist.GetGeoTransform() == dem.GetGeoTransform()
d, n = dist.ReadAsArray(), near.ReadAsArray()
assert d.shape == (100, 120) and (d == -1).sum() > 335 and set(n.flatten()) == {-1, 0, 1}
walk = json.load(open(f"{t}/walk.geojson"))["features"][0]
assert walk["geometry"]["type"] == "LineString" and walk["properties"]["length"] > 3000
assert open(f"{t}/isochrones.png", "rb").read(8) == b"\x89PNG\r\n\x1a\n"
PY
echo "terrain example: ok"
