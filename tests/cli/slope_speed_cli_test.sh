#!/usr/bin/env bash
# geodex travel time with a slope-dependent speed (--speed tobler --cost-epsilon 0.05, --speed table:FILE.csv,
# --inbound) on DEMs, as a hiker's planner runs it: inclined GeoTIFFs made here with GDAL's Python
# bindings; answers are analytic (Tobler's speed along a contour, up and down a 5% grade, the
# switchbacks up a 45-degree slope). Also run in remote mode (remote_mode.sh).
# Env: GEODEX (the binary).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
PY=/usr/bin/python3

$PY - "$tmp" <<'PY'
import math, sys
import numpy as np
from osgeo import gdal, osr
gdal.UseExceptions()
out = sys.argv[1]
def write(name, a, x0=500000, y0=5000000, d=10):
    h, w = a.shape
    ds = gdal.GetDriverByName("GTiff").Create(f"{out}/{name}", w, h, 1, gdal.GDT_Float64)
    ds.SetGeoTransform((x0, d, 0, y0, 0, -d))
    s = osr.SpatialReference(); s.ImportFromEPSG(32633); ds.SetProjection(s.ExportToWkt())
    ds.GetRasterBand(1).WriteArray(a)
    ds = None
# 40 x 30 cells of 10 m rising to the north: a 5% grade and a 45-degree slope.
i, j = np.meshgrid(np.arange(40), np.arange(30))
north = (29.5 - j) * 10
write("grade5.tif", 0.05 * north)
write("steep45.tif", 1.0 * north)
# Tobler's speed every 0.1 degrees, as a table.
with open(f"{out}/tobler.csv", "w") as f:
    f.write("slope_deg,speed_kmh\n")
    for k in range(-850, 851):
        f.write(f"{k / 10},{6 * math.exp(-3.5 * abs(math.tan(math.radians(k / 10)) + 0.05))}\n")
PY
check "fixtures made" test -s "$tmp/grade5.tif"
G="$tmp/grade5.tif"
tobler='import math
def tobler(s): return 6 * math.exp(-3.5 * abs(s + 0.05))
def per_metre(s): return 3.6 / tobler(s)'

# Along a contour of the 5% grade (370 m east): 370 m / Tobler(0) within 1%.
"$GEODEX" distances "$G" --sources g:500015:4999855 --at g:500385:4999855 --speed tobler --cost-epsilon 0.05 \
  --format json >"$tmp/contour.json"
check "contour: exit 0" test $? -eq 0
check "contour: 370 m / Tobler(0) within 1%; says seconds, Tobler, no proven bound" $PY -c "
$tobler
import json
a = json.load(open('$tmp/contour.json'))
assert a['unit'] == 's' and a['speed'] == 'tobler' and a['bound'] is False, a
assert a['inbound'] is False, a
t, want = a['points'][0]['time_s'], 370 * per_metre(0)
assert abs(t / want - 1) < 0.01, (t, want)"

# Up and down the grade (290 m north-south): each within 1% of its analytic time, their ratio
# e^0.35; --inbound from the bottom gives the time down to it.
B=g:500205:4999705
T=g:500205:4999995
"$GEODEX" distances "$G" --sources $B --at $T --speed tobler --cost-epsilon 0.05 --format json >"$tmp/up.json"
"$GEODEX" distances "$G" --sources $T --at $B --speed tobler --cost-epsilon 0.05 --format json >"$tmp/down.json"
"$GEODEX" distances "$G" --sources $B --at $T --speed tobler --cost-epsilon 0.05 --inbound --format json >"$tmp/in.json"
check "grade: up and down within 1%, ratio e^0.35, inbound = the way down" $PY -c "
$tobler
import json
t = lambda n: json.load(open('$tmp/' + n + '.json'))['points'][0]['time_s']
L = 290 * math.hypot(1, 0.05)
up, down, inb = t('up'), t('down'), t('in')
assert abs(up / (L * per_metre(0.05)) - 1) < 0.01, up
assert abs(down / (L * per_metre(-0.05)) - 1) < 0.01, down
assert abs(up / down / math.exp(0.35) - 1) < 0.01, (up, down)
assert abs(inb / down - 1) < 1e-9, (inb, down)
assert json.load(open('$tmp/in.json'))['inbound'] is True"

# Without --cost-epsilon: a slope speed's default spacing (0.125), a constant speed's bound (0.01).
"$GEODEX" distances "$G" --sources $B --at $T --speed tobler --format json >"$tmp/up_default.json"
"$GEODEX" distances "$G" --sources $B --at $T --speed constant:3.6 --format json >"$tmp/flat_default.json"
check "default epsilon: 0.125 for Tobler (still within 1%); a constant speed with one weight exact" $PY -c "
$tobler
import json
up = json.load(open('$tmp/up_default.json')); flat = json.load(open('$tmp/flat_default.json'))
assert up['epsilon'] == 0.125 and up['bound'] is False, up
assert abs(up['points'][0]['time_s'] / (290 * math.hypot(1, 0.05) * per_metre(0.05)) - 1) < 0.01, up
assert flat['epsilon'] == 0 and flat['exact'] is True and flat['bound'] is True, flat"

# Up the 45-degree slope: the switchbacks (the analytic minimum over symmetric zigzags) within
# 2%, and far below straight up.
"$GEODEX" distances "$tmp/steep45.tif" --sources $B --at $T --speed tobler --cost-epsilon 0.05 --format json >"$tmp/steep.json"
check "45 degrees: the switchback time within 2%" $PY -c "
$tobler
import json
t = json.load(open('$tmp/steep.json'))['points'][0]['time_s']
L = 290 * math.sqrt(2)
best = min(per_metre(math.tan(math.asin(math.sin(math.pi / 4) * math.cos(p)))) / math.cos(p)
           for p in [k * 1e-5 for k in range(157000)])
assert abs(t / (L * best) - 1) < 0.02, (t, L * best)
assert t < L * per_metre(1) / 3, t"

# A table equal to Tobler sampled every 0.1 degrees gives Tobler's times.
"$GEODEX" distances "$G" --sources $B --at $T,g:500385:4999855 --speed "table:$tmp/tobler.csv" --cost-epsilon 0.05 \
  --format json >"$tmp/table.json"
check "table: Tobler's times within 0.1%" $PY -c "
import json
a = json.load(open('$tmp/table.json'))
assert a['speed'] == 'table', a
up = json.load(open('$tmp/up.json'))['points'][0]['time_s']
assert abs(a['points'][0]['time_s'] / up - 1) < 1e-3, (a, up)"

# Matrices are row to column (up != down); isochrones in walking minutes.
"$GEODEX" matrix "$G" --sources $B,$T --targets $B,$T --speed tobler --cost-epsilon 0.05 --format json >"$tmp/m.json"
check "matrix: asymmetric, row to column" $PY -c "
import json
m = json.load(open('$tmp/m.json'))
v = m['distances'] if 'distances' in m else m['values']
up = json.load(open('$tmp/up.json'))['points'][0]['time_s']
down = json.load(open('$tmp/down.json'))['points'][0]['time_s']
assert abs(v[0][1] / up - 1) < 1e-9 and abs(v[1][0] / down - 1) < 1e-9, v"
"$GEODEX" isolines "$G" --sources $B --levels 1min,2min,3min --speed tobler --cost-epsilon 0.05 \
  --output "$tmp/iso.geojson" --crs native
check "isochrones in minutes: exit 0" test $? -eq 0
check "isochrones: valid polygons in seconds, area growing with the level" $PY -c "
import json
from osgeo import ogr
areas = {}
for x in json.load(open('$tmp/iso.geojson'))['features']:
    g = ogr.CreateGeometryFromJson(json.dumps(x['geometry']))
    p = x['properties']
    assert g.IsValid() and p['units'] == 's', p
    assert p['bound'] is False and p['speed'] == 'tobler' and p['inbound'] is False, p
    areas[x['properties']['level']] = areas.get(x['properties']['level'], 0) + g.GetArea()
assert sorted(areas) == [60, 120, 180], areas
assert 0 < areas[60] < areas[120] < areas[180], areas"

# Errors name the flag (exit 2).
printf 'slope_deg,speed_kmh\n-10,4\nsteep,2\n' >"$tmp/bad_row.csv"
printf '5,4\n10,3\n' >"$tmp/no_level.csv"
printf -- '-10,4\n-10,5\n' >"$tmp/repeat.csv"
expect_error "no table" "--speed table:$tmp/none.csv: cannot open" distances "$G" --sources 0 --speed "table:$tmp/none.csv"
expect_error "table row" "line 3: 'steep,2' is not 'slope_deg,speed_kmh'" distances "$G" --sources 0 --speed "table:$tmp/bad_row.csv"
expect_error "table level" "--speed: must cover slope 0" distances "$G" --sources 0 --speed "table:$tmp/no_level.csv"
expect_error "table order" "slope -10 does not increase" distances "$G" --sources 0 --speed "table:$tmp/repeat.csv"
expect_error "inbound path" "--inbound: a path is walked from its start" path "$G" --from 0 --to 5 --speed tobler --cost-epsilon 0.05 --inbound
expect_error "inbound alone" "--inbound: a travel cost needs --speed" distances "$G" --sources 0 --inbound

finish "slope_speed_cli"
