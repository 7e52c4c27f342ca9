#!/usr/bin/env bash
# Travel answers a user can trust at the seams: repeated flags add up or are refused, friction
# polygons that cannot be used are refused (never dropped in silence), and isochrones are never cut
# by a --max-distance at or above their top level, given in the levels' own units. Fixtures are
# GeoTIFFs and GeoJSON made here with GDAL's Python bindings. Also run in remote mode.
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
ds = gdal.GetDriverByName("GTiff").Create(f"{out}/flat.tif", 40, 30, 1, gdal.GDT_Float64)
ds.SetGeoTransform((500000, 10, 0, 5000000, 0, -10))
s = osr.SpatialReference(); s.ImportFromEPSG(32633); ds.SetProjection(s.ExportToWkt())
ds.GetRasterBand(1).WriteArray(np.full((30, 40), 100.0)); ds = None
def box(x0, y0, x1, y1):
    return [[[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]]]
def collection(features):
    return {"type": "FeatureCollection",
            "crs": {"type": "name", "properties": {"name": "EPSG:32633"}}, "features": features}
def feature(props, coords):
    return {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": coords}}
# Two walls, each leaving a gap the other closes: together they cut off the east of the map.
wall_a = feature({}, box(500195, 4999800, 500205, 5000100))   # from y 4999800 north past the edge
wall_b = feature({}, box(500195, 4999600, 500205, 4999810))   # the south part, overlapping a
json.dump(collection([wall_a]), open(f"{out}/wall_a.geojson", "w"))
json.dump(collection([wall_b]), open(f"{out}/wall_b.geojson", "w"))
json.dump(collection([wall_a, wall_b]), open(f"{out}/walls.geojson", "w"))
# Two friction bands, and the file holding both.
band_a = feature({"friction": 4}, box(500100, 4999000, 500200, 5001000))
band_b = feature({"friction": 0.5}, box(500250, 4999000, 500300, 5001000))
json.dump(collection([band_a]), open(f"{out}/band_a.geojson", "w"))
json.dump(collection([band_b]), open(f"{out}/band_b.geojson", "w"))
json.dump(collection([band_a, band_b]), open(f"{out}/bands.geojson", "w"))
# Friction polygons that cannot be used as drawn.
text = json.dumps(collection([feature({"friction": 4}, box(500100, 4999000, 500200, 5001000))]))
open(f"{out}/huge.geojson", "w").write(text.replace("500200", "1e999", 1))
open(f"{out}/nan.geojson", "w").write(text.replace("500200", "NaN", 1))
json.dump(collection([feature({"friction": 4}, [[[500100, 4999000], [500200, 4999000], [500100, 4999000]]])]),
          open(f"{out}/two_points.geojson", "w"))
json.dump(collection([feature({"friction": 4}, box(500100, 4999000, 1e308, 5001000))]),
          open(f"{out}/far.geojson", "w"))
# A 2000-vertex circle of friction 3: cut into the grid exactly it leaves slivers, and a path's
# travel graph there needs ~60M Steiner points (the issue's blow-up, on a smaller map).
import math
ring = [[500200 + 100 * math.cos(2 * math.pi * i / 2000), 4999850 + 100 * math.sin(2 * math.pi * i / 2000)]
        for i in range(2000)]
json.dump(collection([feature({"friction": 3}, [ring + [ring[0]]])]), open(f"{out}/circle.geojson", "w"))
PY
check "fixtures made" test -s "$tmp/flat.tif"
F="$tmp/flat.tif"
S=g:500015:4999985
AT=g:500315:4999876.81,g:500315:4999725

# --barrier twice cuts what one file holding both cuts: the east is cut off (inf) by the two walls
# together, and reachable around either alone.
"$GEODEX" distances "$F" --sources $S --at $AT --barrier "$tmp/wall_a.geojson" \
  --barrier "$tmp/wall_b.geojson" --format json >"$tmp/two.json"
check "two barriers: exit 0" test $? -eq 0
"$GEODEX" distances "$F" --sources $S --at $AT --barrier "$tmp/walls.geojson" --format json >"$tmp/merged.json"
"$GEODEX" distances "$F" --sources $S --at $AT --barrier "$tmp/wall_a.geojson" --format json >"$tmp/one.json"
check "two barriers: the same answers as the merged file, and not those of one alone" $PY -c "
import json
two, merged, one = (json.load(open('$tmp/%s.json' % k))['points'] for k in ('two', 'merged', 'one'))
assert two == merged, (two, merged)
assert all(p['exact'] is None for p in two), two
assert all(p['exact'] is not None for p in one), one"

# On a mesh kept by the server (named, not a local file), each --barrier file is one DeriveMesh
# on the one before: the two walls cut it apart as the merged file does. (Remote mode only.)
if [ "${GEODEX_MODE:-local}" = remote ]; then
  $PY - "$tmp" <<'PY'
import json, sys
out = sys.argv[1]
n = 21  # a 20 x 20 square of unit cells, vertex (i, j) = j * 21 + i
with open(f"{out}/sq.off", "w") as f:
    f.write("OFF\n%d %d 0\n" % (n * n, 2 * 20 * 20))
    for j in range(n):
        for i in range(n):
            f.write("%d %d 0\n" % (i, j))
    for j in range(20):
        for i in range(20):
            a = j * n + i
            f.write("3 %d %d %d\n3 %d %d %d\n" % (a, a + 1, a + n + 1, a, a + n + 1, a + n))
def walls(boxes):
    return {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [
            [[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]]]}} for x0, y0, x1, y1 in boxes]}
a, b = (9.5, 8, 10.5, 25), (9.5, -5, 10.5, 8.5)
for name, boxes in (("sq_a", [a]), ("sq_b", [b]), ("sq_ab", [a, b])):
    json.dump(walls(boxes), open(f"{out}/{name}.geojson", "w"))
PY
  "$GEODEX" mesh upload "$tmp/sq.off" --name trust-square >/dev/null
  check "server mesh uploaded" test $? -eq 0
  for k in two merged one; do
    case $k in
      two) b=(--barrier "$tmp/sq_a.geojson" --barrier "$tmp/sq_b.geojson") ;;
      merged) b=(--barrier "$tmp/sq_ab.geojson") ;;
      one) b=(--barrier "$tmp/sq_a.geojson") ;;
    esac
    "$GEODEX" distances trust-square --sources 0 --at 440,20 "${b[@]}" --format json \
      >"$tmp/sq_$k.json" 2>/dev/null
    check "server mesh, barriers $k: exit 0" test $? -eq 0
  done
  check "server mesh: two barrier files cut what the merged file cuts" $PY -c "
import json
two, merged, one = (json.load(open('$tmp/sq_%s.json' % k))['points'] for k in ('two', 'merged', 'one'))
assert [p['exact'] for p in two] == [p['exact'] for p in merged], (two, merged)
assert all(p['exact'] is None for p in two), two
assert all(p['exact'] is not None for p in one), one"
fi

# --friction twice (polygon files) adds up: the same times as the file holding both bands.
for k in two merged; do
  if [ $k = two ]; then fr=(--friction "$tmp/band_a.geojson" --friction "$tmp/band_b.geojson");
  else fr=(--friction "$tmp/bands.geojson"); fi
  "$GEODEX" distances "$F" --sources $S --at $AT --speed constant:3.6 "${fr[@]}" \
    --format json >"$tmp/fr_$k.json"
  check "friction $k: exit 0" test $? -eq 0
done
"$GEODEX" distances "$F" --sources $S --at $AT --speed constant:3.6 --friction "$tmp/band_b.geojson" \
  --format json >"$tmp/fr_b.json"
check "two friction files: the merged file's times, not the last file's" $PY -c "
import json
two, merged, b = (json.load(open('$tmp/fr_%s.json' % k))['points'] for k in ('two', 'merged', 'b'))
assert [p['time_s'] for p in two] == [p['time_s'] for p in merged], (two, merged)
assert two[0]['time_s'] > b[0]['time_s'] + 200, (two, b)"

# A flag that takes one value, given twice, is refused naming it (it used to keep the last).
expect_error "speed twice" "option --speed given twice" distances "$F" --sources $S --speed constant:3.6 --speed constant:7.2
expect_error "output twice" "option --output given twice" distances "$F" --sources $S --output "$tmp/a.tif" --output "$tmp/b.tif"
expect_error "raster friction repeated" "only polygon files add up" distances "$F" --sources $S --speed constant:3.6 --friction "$tmp/band_a.geojson" --friction "$F"
# --sources twice is one list.
"$GEODEX" distances "$F" --sources $S --sources g:500315:4999725 --at g:500200:4999900 --format json >"$tmp/s2.json"
"$GEODEX" distances "$F" --sources $S,g:500315:4999725 --at g:500200:4999900 --format json >"$tmp/s1.json"
check "sources twice: one list" cmp -s "$tmp/s1.json" "$tmp/s2.json"

# Friction polygons that cannot be used are refused naming --friction and the feature.
for bad in huge nan two_points far; do
  expect_error "friction $bad" "--friction $tmp/$bad.geojson: feature 0" \
    distances "$F" --sources $S --speed constant:3.6 --friction "$tmp/$bad.geojson"
done

# Isochrones: --max-distance in the levels' units, and a top level at or below it is whole.
"$GEODEX" isolines "$F" --sources g:500195:4999855 --levels 1min,2min --speed constant:3.6 \
  --output "$tmp/iso.geojson" --crs native
check "isochrones: exit 0" test $? -eq 0
for md in 2min 120 3min; do
  "$GEODEX" isolines "$F" --sources g:500195:4999855 --levels 1min,2min --speed constant:3.6 \
    --max-distance $md --output "$tmp/iso_$md.geojson" --crs native
  check "isochrones --max-distance $md: exit 0" test $? -eq 0
  check "isochrones --max-distance $md: the same polygons as without it" $PY -c "
import json
a, b = (json.load(open(p))['features'] for p in ('$tmp/iso.geojson', '$tmp/iso_$md.geojson'))
ga = sorted((f['properties']['level'], json.dumps(f['geometry'])) for f in a)
gb = sorted((f['properties']['level'], json.dumps(f['geometry'])) for f in b)
assert ga == gb, 'differ'"
done
expect_error "max-distance time without speed" "--max-distance: '2min' is a time" isolines "$F" --sources $S --levels 10,20 --max-distance 2min

# A limit's message suggests only what applies: a travel solve over its window budget is not told
# to use --lambda, which --speed refuses. (--max-windows is local; geodexd has its own flag.)
if [ "${GEODEX_MODE:-local}" = local ]; then
  "$GEODEX" distances "$F" --sources $S --speed constant:3.6 --max-windows 50 >/dev/null 2>"$tmp/err.txt"
  rc=$?
  check "travel window budget: exit 1 ($rc)" test "$rc" -eq 1
  check "travel window budget: says so" grep -q "window budget exceeded" "$tmp/err.txt"
  check "travel window budget: no --lambda suggested" bash -c "! grep -q lambda '$tmp/err.txt'"
  "$GEODEX" distances "$F" --sources $S --max-windows 50 >/dev/null 2>"$tmp/err.txt"
  check "plain window budget: lambda suggested" grep -q "lambda > 0" "$tmp/err.txt"
fi

# A path across the slivers of an exactly cut 2000-vertex circle: it ran minutes on the Steiner
# graph (60M points) and is now traced through the regions, the field's own engine: its time is
# the field's at its end, to the digit, within the test's bound of 60 s.
CIRCLE=(--speed constant:3.6 --friction "$tmp/circle.geojson" --friction-boundaries exact)
timeout 60 "$GEODEX" path "$F" --from $S --to g:500315:4999725 "${CIRCLE[@]}" --format json \
  >"$tmp/circle_path.json" 2>"$tmp/err.txt"
check "sliver path: answered ($?)" test -s "$tmp/circle_path.json"
timeout 60 "$GEODEX" distances "$F" --sources $S --at g:500315:4999725 "${CIRCLE[@]}" \
  --format json >"$tmp/circle_at.json"
check "sliver path: its time is the field's at its end" $PY -c "
import json
p = json.load(open('$tmp/circle_path.json')); f = json.load(open('$tmp/circle_at.json'))
assert abs(p['time_s'] - f['points'][0]['time_s']) <= 1e-9 * p['time_s'], (p['time_s'], f)"
# Default work budgets (CLI and geodexd alike): a graph search (Tobler's speed) over its budget is
# refused naming --max-windows (the graph ignored the budget before), and a graph needing more
# Steiner points than allowed is refused up front naming --max-steiner-points.
if [ "${GEODEX_MODE:-local}" = local ]; then
  "$GEODEX" path "$F" --from $S --to g:500315:4999725 --speed tobler --max-windows 10 \
    >/dev/null 2>"$tmp/err.txt"
  rc=$?
  check "graph work budget: exit 1 ($rc)" test "$rc" -eq 1
  check "graph work budget: says so, naming --max-windows" \
    grep -q "work budget exceeded.*(--max-windows)" "$tmp/err.txt"
  "$GEODEX" path "$F" --from $S --to g:500315:4999725 --speed tobler --max-steiner-points 1000 \
    >/dev/null 2>"$tmp/err.txt"
  rc=$?
  check "graph points: exit 1 ($rc)" test "$rc" -eq 1
  check "graph points: names --max-steiner-points" grep -q -- "--max-steiner-points" "$tmp/err.txt"
fi

# Metres and seconds, both, labelled: a 7.2 km/h (2 m/s) path's JSON and GeoJSON carry length_m
# (metres along the surface) and time_s (within the bound of length_m / 2); a time raster's band
# says travel time in seconds, a distance raster's geodesic distance in metres.
"$GEODEX" path "$F" --from $S --to g:500315:4999876.81 --speed constant:7.2 --format json >"$tmp/p.json"
check "path json: exit 0" test $? -eq 0
"$GEODEX" path "$F" --from $S --to g:500315:4999876.81 --speed constant:7.2 \
  --output "$tmp/p.geojson" --crs native
check "path geojson: exit 0" test $? -eq 0
"$GEODEX" path "$F" --from $S --to g:500315:4999876.81 --format json >"$tmp/p_m.json"
check "path: length_m is metres, time_s seconds, in JSON and GeoJSON alike" $PY -c "
import json, math
p = json.load(open('$tmp/p.json')); m = json.load(open('$tmp/p_m.json'))
g = json.load(open('$tmp/p.geojson'))['features'][0]['properties']
line = math.hypot(300, 108.19)
assert abs(m['length_m'] - line) < 1e-6 * line, m
assert abs(p['length_m'] - m['length_m']) < 1e-6 * line, (p, m)
assert p['length_m'] / 2 * (1 - 1e-9) <= p['time_s'] <= p['length_m'] / 2 * 1.01, p
assert abs(g['length_m'] - p['length_m']) < 1e-9 * line and g['time_s'] == p['time_s'], g
assert g.get('units') != 'm' or g['length'] == g['length_m'], g"
"$GEODEX" distances "$F" --sources $S --at $AT --speed constant:7.2 --output "$tmp/pts.geojson" --crs native
check "points geojson: exit 0" test $? -eq 0
check "points: seconds are time_s in units s, not a distance" $PY -c "
import json
for f in json.load(open('$tmp/pts.geojson'))['features']:
    p = f['properties']
    assert p['units'] == 's' and 'distance' not in p and p['time_s'] > 0, p"
"$GEODEX" distances "$F" --sources $S --speed constant:7.2 --output "$tmp/t.tif"
"$GEODEX" distances "$F" --sources $S --output "$tmp/d.tif"
check "rasters: travel time in s, geodesic distance in m" $PY -c "
from osgeo import gdal
ts, ds = gdal.Open('$tmp/t.tif'), gdal.Open('$tmp/d.tif')  # kept open while their bands are read
t, d = ts.GetRasterBand(1), ds.GetRasterBand(1)
assert t.GetDescription() == 'travel time' and t.GetUnitType() == 's', (t.GetDescription(), t.GetUnitType())
assert d.GetDescription() == 'geodesic distance' and d.GetUnitType() == 'm', (d.GetDescription(), d.GetUnitType())"

# Every GIS file records what made it: the software, the command line, what the values are and,
# for times, the speed and the bound (a raster's GEODEX_* metadata, a GeoJSON's "geodex" member).
check "rasters record what made them" $PY -c "
from osgeo import gdal
t, d = gdal.Open('$tmp/t.tif').GetMetadata(), gdal.Open('$tmp/d.tif').GetMetadata()
assert t['GEODEX_SOFTWARE'].startswith('geodex ') and t['TIFFTAG_SOFTWARE'] == t['GEODEX_SOFTWARE'], t
assert t['GEODEX_MADE_BY'].startswith('geodex distances ') and '--speed constant:7.2' in t['GEODEX_MADE_BY'], t
assert (t['GEODEX_VALUES'], t['GEODEX_UNITS'], t['GEODEX_SPEED']) == ('travel time', 's', 'constant 7.2 km/h'), t
assert (t['GEODEX_EXACT'], t['GEODEX_EPSILON'], t['GEODEX_BOUND']) == ('true', '0', 'true'), t
assert (d['GEODEX_VALUES'], d['GEODEX_UNITS'], d['GEODEX_EXACT']) == ('geodesic distance', 'm', 'true'), d
assert 'GEODEX_SPEED' not in d, d"
check "GeoJSON records what made it" $PY -c "
import json
g = json.load(open('$tmp/p.geojson'))['geodex']
assert g['software'].startswith('geodex ') and g['made_by'].startswith('geodex path '), g
assert (g['values'], g['units'], g['speed'], g['exact']) == ('travel time', 's', 'constant 7.2 km/h', 'true'), g"

finish "travel_trust_cli"
