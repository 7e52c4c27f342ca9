#!/usr/bin/env bash
# geodex travel time on DEMs (--speed, --friction, --max-slope, --face-weights, --levels in
# minutes), as a GIS user runs it: fixtures are GeoTIFFs and GeoJSON made here with GDAL's Python
# bindings; answers are analytic (straight lines at a known speed, a band of known friction, a
# ridge of known slope) within the stated bound; rasters and isochrones are read back with GDAL.
# Also run in remote mode (remote_mode.sh): friction and weights are read here and sent as face
# weights; geodexd solves.
# Env: GEODEX (the binary).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
PY=/usr/bin/python3

$PY - "$tmp" <<'PY'
import json, sys
import numpy as np
from osgeo import gdal, osr
gdal.UseExceptions()
out = sys.argv[1]
def write(name, epsg, a, nodata=None, x0=500000, y0=5000000, d=10):
    h, w = a.shape
    ds = gdal.GetDriverByName("GTiff").Create(f"{out}/{name}", w, h, 1, gdal.GDT_Float64)
    ds.SetGeoTransform((x0, d, 0, y0, 0, -d))
    s = osr.SpatialReference(); s.ImportFromEPSG(epsg); ds.SetProjection(s.ExportToWkt())
    b = ds.GetRasterBand(1)
    if nodata is not None: b.SetNoDataValue(nodata)
    b.WriteArray(a)
    ds = None
# flat.tif: 40 x 30 cells of 10 m at 100 m.
write("flat.tif", 32633, np.full((30, 40), 100.0))
# ridge.tif: a north-south ridge across the whole map, its flanks 40 degrees steep over columns
# 15-24 (x from 500150 to 500250), flat on both sides.
i, j = np.meshgrid(np.arange(40), np.arange(30))
x = (i + 0.5) * 10
z = np.tan(np.radians(40)) * np.clip(50 - np.abs(x - 200), 0, None)
write("ridge.tif", 32633, z)
# friction.tif on flat.tif's grid: 4 in columns 10-19 (a 100 m band), 1 elsewhere.
f = np.ones((30, 40)); f[:, 10:20] = 4
write("friction.tif", 32633, f)
write("friction_utm32.tif", 32632, f)
# The same band as polygons, in the DEM's CRS named by an identifier.
band = {"type": "FeatureCollection",
        "crs": {"type": "name", "properties": {"name": "EPSG:32633"}},
        "features": [{"type": "Feature", "properties": {"friction": 4},
                      "geometry": {"type": "Polygon", "coordinates": [[
                          [500100, 4999000], [500200, 4999000], [500200, 5001000],
                          [500100, 5001000], [500100, 4999000]]]}}]}
json.dump(band, open(f"{out}/band.geojson", "w"))
PY
check "fixtures made" test -s "$tmp/flat.tif"
F="$tmp/flat.tif"

# A straight line about 20 degrees off the grid's axes at 3.6 km/h (1 m/s): the time is the
# distance, within the bound (1 + 0.01); at 7.2 km/h half of it.
"$GEODEX" distances "$F" --sources g:500015:4999985 --at g:500315:4999876.81 \
  --speed constant:3.6 --format json >"$tmp/at.json"
check "at: exit 0" test $? -eq 0
"$GEODEX" distances "$F" --sources g:500015:4999985 --at g:500315:4999876.81 \
  --speed constant:7.2 --cost-epsilon 0.003 --format json >"$tmp/at_fast.json"
# One weight is the exact engine: the answer says exact (epsilon 0), not approximate.
check "at: time = distance / speed; says seconds and exact" $PY -c "
import json, math
a = json.load(open('$tmp/at.json')); b = json.load(open('$tmp/at_fast.json'))
d = math.hypot(300, 108.19)
assert a['unit'] == 's' and a['approximate'] is False and a['exact'] is True, a
assert a['epsilon'] == 0 and b['epsilon'] == 0, (a, b)
t = a['points'][0]['time_s']
assert abs(t - d) <= 1e-9 * d, (t, d)  # exact: the straight line on the plane
t2 = b['points'][0]['time_s']
assert abs(t2 - d / 2) <= 1e-9 * d, (t2, d / 2)"

# Friction: a 100 m band of friction 4 across the map costs 3 x 100 s more to cross at 1 m/s,
# drawn as polygons or as a raster. Faces take the friction under their centroids, so the band's
# edges follow the triangles: 90 to 100 m of it are crossed. With --friction-boundaries exact the
# polygons' outlines are cut into the DEM's mesh: exactly 100 m (270 + 400 s, within the bound).
for fr in band.geojson friction.tif exact exact_snap; do
  extra=()
  file=$fr low=640
  [ "$fr" = exact ] && extra=(--friction-boundaries exact) file=band.geojson low=670
  [ "$fr" = exact_snap ] && extra=(--friction-boundaries exact --friction-snap 0.1) file=band.geojson low=670
  "$GEODEX" distances "$F" --sources g:500015:4999855 --at g:500385:4999855 \
    --speed constant:3.6 --friction "$tmp/$file" "${extra[@]}" --format json >"$tmp/band_$fr.json"
  check "friction $fr: exit 0" test $? -eq 0
  check "friction $fr: 370 m with 100 m (by faces: 90-100 m) at friction 4 takes $low-670 s" $PY -c "
import json; t = json.load(open('$tmp/band_$fr.json'))['points'][0]['time_s']
assert $low * (1 - 1e-9) <= t <= 670 * 1.01, t"
done

# --max-slope: the 40-degree ridge is crossed under 45 and blocks under 35 (the far side is
# unreachable; the near side is not).
R="$tmp/ridge.tif"
"$GEODEX" distances "$R" --sources g:500015:4999855 --at g:500385:4999855,g:500100:4999855 \
  --speed constant:3.6 --max-slope 45 --format json >"$tmp/climb.json"
"$GEODEX" distances "$R" --sources g:500015:4999855 --at g:500385:4999855,g:500100:4999855 \
  --speed constant:3.6 --max-slope 35 --format json >"$tmp/cliff.json"
check "max-slope: 45 crosses the ridge over its flanks, 35 blocks it" $PY -c "
import json, math
a = json.load(open('$tmp/climb.json'))['points']; b = json.load(open('$tmp/cliff.json'))['points']
# Along the row (the ridge is the same at every y) the path is the profile through the cell
# centres x = 5, 15, ..., from x = 15 to x = 385.
z = lambda x: math.tan(math.radians(40)) * max(50 - abs(x - 200), 0)
xs = [15 + 10 * k for k in range(38)]
over = sum(math.hypot(10, z(b) - z(a)) for a, b in zip(xs, xs[1:]))
assert over * (1 - 1e-6) <= a[0]['time_s'] <= over * 1.01, (a[0], over)
assert b[0]['time_s'] is None and b[0]['source'] is None, b[0]
assert abs(b[1]['time_s'] - 85) < 1, b[1]"

# Isochrones in minutes (GeoJSON polygons): 1 and 2 minutes at 3.6 km/h are discs of 60 and 120 m
# (within the bound and the grid), valid, the larger with the larger area.
"$GEODEX" isolines "$F" --sources g:500195:4999855 --levels 1min,2min --speed constant:3.6 \
  --output "$tmp/iso.geojson" --crs native
check "isochrones: exit 0" test $? -eq 0
check "isochrones in minutes: valid polygons in seconds, area growing with the level" $PY -c "
import json, math
from osgeo import ogr
f = json.load(open('$tmp/iso.geojson'))['features']
areas = {}
for x in f:
    g = ogr.CreateGeometryFromJson(json.dumps(x['geometry']))
    assert g.IsValid(), x['properties']
    assert x['properties']['units'] == 's' and x['properties']['epsilon'] == 0, x['properties']
    assert x['properties']['exact'] is True, x['properties']
    assert x['properties']['bound'] is True and x['properties']['speed'] == 'constant', x['properties']
    areas[x['properties']['level']] = areas.get(x['properties']['level'], 0) + g.GetArea()
assert sorted(areas) == [60, 120], areas
for r in (60, 120):
    assert math.pi * (r / 1.01) ** 2 * 0.95 <= areas[r] <= math.pi * r * r * 1.01, (r, areas[r])"

# A time raster on the DEM's grid: each cell's time is its distance at 1 m/s.
"$GEODEX" distances "$F" --sources g:500015:4999985 --speed constant:3.6 --output "$tmp/t.tif"
check "time raster: exit 0" test $? -eq 0
check "time raster: cell (30, 20) is its distance in seconds" $PY -c "
from osgeo import gdal
a = gdal.Open('$tmp/t.tif').ReadAsArray()
import math; d = math.hypot(290, 190)
assert d * (1 - 1e-6) <= a[20, 30] <= d * 1.01, a[20, 30]"

# Paths and matrices say what they are.
"$GEODEX" path "$F" --from g:500015:4999985 --to g:500315:4999876.81 --speed constant:3.6 \
  --format json >"$tmp/path.json"
check "path: time_s and length" $PY -c "
import json, math; p = json.load(open('$tmp/path.json'))
assert p['unit'] == 's' and p['time_s'] >= p['length'] * (1 - 1e-9), p
assert abs(p['length'] - math.hypot(300, 108.19)) < 0.01 * p['length'], p['length']"
"$GEODEX" matrix "$F" --sources g:500015:4999985,g:500315:4999876.81 \
  --targets g:500015:4999985,g:500315:4999876.81 --speed constant:3.6 >"$tmp/m.txt"
check "matrix: a header saying seconds and the bound" grep -q "^# travel time in seconds" "$tmp/m.txt"

# Several weights are answered within the bound, and say so: approximate, epsilon 0.01.
"$GEODEX" distances "$F" --sources g:500015:4999985 --at g:500315:4999876.81 --speed constant:3.6 \
  --friction "$tmp/friction.tif" --format json >"$tmp/at_fr.json"
check "at with friction: says approximate with its bound" $PY -c "
import json; a = json.load(open('$tmp/at_fr.json'))
assert a['approximate'] is True and a['exact'] is False and a['epsilon'] == 0.01 and a['bound'] is True, a"

# --face-weights on a plain mesh: one weight per face; 2 everywhere doubles the time.
printf 'OFF\n4 2 0\n0 0 0\n10 0 0\n10 10 0\n0 10 0\n3 0 1 2\n3 0 2 3\n' >"$tmp/sq.off"
printf '2\n2\n' >"$tmp/w2.txt"
t1=$("$GEODEX" distances "$tmp/sq.off" --sources 0 --speed constant:3.6 | sed -n 4p)
t2=$("$GEODEX" distances "$tmp/sq.off" --sources 0 --speed constant:3.6 --face-weights "$tmp/w2.txt" | sed -n 4p)
check "face weights 2 double the time ($t1, $t2)" $PY -c "assert $t2 == 2 * $t1 and $t1 > 14"

# Errors name the flag (exit 2): a cost flag without --speed, a bad speed, epsilon out of range,
# friction in another CRS, friction on a plain mesh, weights of the wrong count, a time level
# without --speed, directions with a travel cost.
expect_error "no speed" "--max-slope: a travel cost needs --speed" distances "$F" --sources 0 --max-slope 30
expect_error "bad speed" "--speed: must be > 0" distances "$F" --sources 0 --speed constant:0
expect_error "speed syntax" "--speed: 'walking' is not constant:KMH" distances "$F" --sources 0 --speed walking
expect_error "epsilon" "--cost-epsilon: must be in (0, 1)" distances "$F" --sources 0 --speed constant:5 --cost-epsilon 2
expect_error "friction CRS" "is not the DEM's" distances "$F" --sources 0 --speed constant:5 --friction "$tmp/friction_utm32.tif"
expect_error "friction on a mesh" "friction maps need a DEM" distances "$tmp/sq.off" --sources 0 --speed constant:5 --friction "$tmp/band.geojson"
# --friction-snap: the band's sides lie 5 m from the cell centres, outside its 1 m discs: as drawn.
check "friction-snap 0.1 leaves outlines its discs do not reach as drawn: the same time" $PY -c "
import json
a, b = (json.load(open('$tmp/band_%s.json' % k))['points'][0]['time_s'] for k in ('exact', 'exact_snap'))
assert a == b, (a, b)"
expect_error "friction-snap range" "--friction-snap: must be in [0, 0.25]" distances "$F" --sources 0 --speed constant:5 --friction "$tmp/band.geojson" --friction-boundaries exact --friction-snap 0.5
expect_error "friction-snap without exact" "--friction-snap: snaps friction outlines cut into the mesh (--friction-boundaries exact" distances "$F" --sources 0 --speed constant:5 --friction "$tmp/band.geojson" --friction-snap 0.1
expect_error "friction-boundaries value" "must be exact or faces" distances "$F" --sources 0 --speed constant:5 --friction "$tmp/band.geojson" --friction-boundaries cut
expect_error "friction-boundaries on a raster" "cuts friction polygons" distances "$F" --sources 0 --speed constant:5 --friction "$tmp/friction.tif" --friction-boundaries exact
printf '1\n' >"$tmp/w1.txt"
expect_error "weights count" "--face-weights:" distances "$tmp/sq.off" --sources 0 --speed constant:5 --face-weights "$tmp/w1.txt"
expect_error "time level" "--levels: '10min' is a time" isolines "$F" --sources 0 --levels 10min
expect_error "directions" "--speed: geodesic directions are read off the exact engine" distances "$F" --sources 0 --speed constant:5 --directions
expect_error "delaunay" "--speed: the geodesic Delaunay triangulation" delaunay "$F" --sites 0,500,900 --speed constant:5

# The engine's memory limit: refused before allocating, naming the flag (exit 1); remotely it is
# geodexd's flag, and the CLI's is refused saying so (exit 2). (Several weights: one weight places
# no Steiner points, docs/travel.md.)
"$GEODEX" distances "$F" --sources 0 --speed constant:5 --friction "$tmp/friction.tif" --max-steiner-points 1000 >/dev/null 2>"$tmp/err.txt"
rc=$?
if [ "${GEODEX_MODE:-local}" = local ]; then
  check "steiner limit: exit 1 ($rc)" test "$rc" -eq 1
  check "steiner limit: names the flag" grep -qF -- "(--max-steiner-points)" "$tmp/err.txt"
else
  check "steiner limit: local only, exit 2 ($rc)" test "$rc" -eq 2
  check "steiner limit: names geodexd's flag" grep -qF -- "--max_steiner_points" "$tmp/err.txt"
fi

finish "travel_cli"
