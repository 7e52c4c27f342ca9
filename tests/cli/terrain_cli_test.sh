#!/usr/bin/env bash
# geodex on DEMs, as a GIS user runs it: fixtures are GeoTIFFs made here with GDAL's Python
# bindings (a tilted plane in UTM 33N, the same area on a longitude/latitude grid, a flat DEM
# with a nodata slot); answers are analytic; rasters written are read back with GDAL.
# Also run in remote mode (remote_mode.sh): a GeoTIFF is then uploaded as it is and read by geodexd.
# Env: GEODEX (the binary).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
PY=/usr/bin/python3

$PY - "$tmp" <<'PY'
import sys
import numpy as np
from osgeo import gdal, osr
gdal.UseExceptions()
out = sys.argv[1]
def write(name, epsg, x0, y0, dx, dy, a, nodata=None):
    h, w = a.shape
    ds = gdal.GetDriverByName("GTiff").Create(f"{out}/{name}", w, h, 1, gdal.GDT_Float64)
    ds.SetGeoTransform((x0, dx, 0, y0, 0, -dy))
    s = osr.SpatialReference(); s.ImportFromEPSG(epsg); ds.SetProjection(s.ExportToWkt())
    b = ds.GetRasterBand(1)
    if nodata is not None: b.SetNoDataValue(nodata)
    b.WriteArray(a)
    ds = None
# plane.tif: z = 0.1 (x - 500000) + 0.2 (y - 4999700) on 40 x 30 cells of 10 m.
i, j = np.meshgrid(np.arange(40), np.arange(30))
x, y = 500000 + (i + 0.5) * 10, 5000000 - (j + 0.5) * 10
write("plane.tif", 32633, 500000, 5000000, 10, 10, 0.1 * (x - 500000) + 0.2 * (y - 4999700))
# slot.tif: flat, nodata in columns 14-15 from row 5 to the bottom edge.
a = np.zeros((30, 30)); a[5:, 14:16] = -9999
write("slot.tif", 32633, 500000, 5000000, 10, 10, a, nodata=-9999)
# strait.tif: land at 3 m, a sea strait at -2 m across the whole map in columns 9-10.
s = np.full((10, 20), 3.0); s[:, 9:11] = -2
write("strait.tif", 32633, 500000, 5000000, 10, 10, s)
# pond.tif: flat, 40 x 40 cells of 10 m, a nodata pond in rows and columns 15-24.
p = np.zeros((40, 40)); p[15:25, 15:25] = -9999
write("pond.tif", 32633, 500000, 5000000, 10, 10, p, nodata=-9999)
PY
check "fixtures made" test -s "$tmp/plane.tif"
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$tmp/tri.off"

# info: the CRS, the grid, the nodata count, metres.
"$GEODEX" info "$tmp/slot.tif" >"$tmp/info.txt"
check "info exits 0" test $? -eq 0
check "info: crs" grep -q "^crs: WGS 84 / UTM zone 33N$" "$tmp/info.txt"
check "info: grid" grep -qx "grid: 30 30" "$tmp/info.txt"
check "info: nodata cells" grep -qx "nodata_cells: 50" "$tmp/info.txt"
check "info: units" grep -qx "units: m" "$tmp/info.txt"
"$GEODEX" info "$tmp/plane.tif" --format json --dem-step 3 >"$tmp/info.json"
check "info json: step, grid, crs" $PY -c "
import json; d = json.load(open('$tmp/info.json'))
assert d['dem_step'] == 3 and d['grid'] == [14, 10] and 'UTM zone 33N' in d['crs'], d"

# A straight geodesic on the plane between two map points (g:X:Y in the DEM's CRS, ll:LON:LAT).
ll=$($PY -c "
from osgeo import osr
a = osr.SpatialReference(); a.ImportFromEPSG(32633)
b = osr.SpatialReference(); b.ImportFromEPSG(4326); b.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
lon, lat, _ = osr.CoordinateTransformation(a, b).TransformPoint(500301.9, 4999722.2)
print(f'll:{lon!r}:{lat!r}')")
"$GEODEX" distances "$tmp/plane.tif" --sources g:500013.3:4999981.7 --at "g:500301.9:4999722.2,$ll" \
  --format json >"$tmp/at.json"
check "map points: exit 0" test $? -eq 0
check "map points: straight-line distance (g: and ll:)" $PY - "$tmp/at.json" <<'PY'
import json, math, sys
z = lambda x, y: 0.1 * (x - 500000) + 0.2 * (y - 4999700)
a, b = (500013.3, 4999981.7), (500301.9, 4999722.2)
want = math.dist((*a, z(*a)), (*b, z(*b)))
pts = json.load(open(sys.argv[1]))["points"]
assert abs(pts[0]["exact"] - want) <= 1e-9 * want, (pts[0], want)
assert abs(pts[1]["exact"] - want) <= 1e-6, (pts[1], want)  # through WGS 84 and back
PY

# A distance raster and the nearest source's index, aligned with the grid; the slot is nodata.
"$GEODEX" distances "$tmp/slot.tif" --sources g:500105:4999845,g:500255:4999845 \
  --output "$tmp/dist.tif" --labels-output "$tmp/near.tif"
check "rasters: exit 0" test $? -eq 0
check "rasters: aligned, nodata in the slot, the detour over the slot" $PY - "$tmp" <<'PY'
import math, sys
import numpy as np
from osgeo import gdal
t = sys.argv[1]
src, d, n = (gdal.Open(f"{t}/{f}.tif") for f in ("slot", "dist", "near"))
assert d.GetGeoTransform() == src.GetGeoTransform() and d.RasterXSize == 30 and d.RasterYSize == 30
assert d.GetSpatialRef().IsSame(src.GetSpatialRef())
a, lab = d.ReadAsArray(), n.ReadAsArray()
assert d.GetRasterBand(1).GetNoDataValue() == -1 and n.GetRasterBand(1).GetNoDataValue() == -1
assert (a[5:, 14:16] == -1).all() and (lab[5:, 14:16] == -1).all()
assert a[15, 10] == 0 and a[15, 25] == 0 and lab[15, 10] == 0 and lab[15, 25] == 1
# Cell (12, 20) sits beside source 0 (10, 15); (17, 20) beside source 1 (25, 15).
assert lab[20, 12] == 0 and lab[20, 17] == 1
assert abs(a[20, 12] - 10 * math.hypot(2, 5)) < 1e-3
PY

# A barrier: with the sea (below 0 m) removed, the far shore is unreachable (inf, nodata in the
# raster); without it the sea is crossed like land.
"$GEODEX" info "$tmp/strait.tif" --barrier-below 0 >"$tmp/info.txt"
check "barrier: cells counted" grep -qx "barrier_cells: 20" "$tmp/info.txt"
"$GEODEX" distances "$tmp/strait.tif" --sources g:500005:4999995 --barrier-below 0 >"$tmp/b.txt"
check "barrier: exit 0" test $? -eq 0
check "barrier: the near shore finite, the far shore inf" $PY - "$tmp/b.txt" <<'PY'
import math, sys
d = [float(x) for x in open(sys.argv[1])]
assert len(d) == 180, len(d)  # 200 cells less the 20 of sea
# Vertices run row by row: 9 near-shore cells, then 9 far-shore cells, per row.
near = [d[r * 18 + c] for r in range(10) for c in range(9)]
far = [d[r * 18 + 9 + c] for r in range(10) for c in range(9)]
assert all(math.isfinite(x) for x in near) and all(math.isinf(x) for x in far)
assert abs(near[8] - 80) < 1e-9  # along the first row to the shore
PY
"$GEODEX" distances "$tmp/strait.tif" --sources g:500005:4999995 --barrier-below 0 \
  --output "$tmp/b.tif"
check "barrier raster: the sea has no surface (nodata -1), the far shore is unreachable (-2)" $PY -c "
from osgeo import gdal; d = gdal.Open('$tmp/b.tif'); a = d.ReadAsArray(); b = d.GetRasterBand(1)
assert (a[:, 9:11] == -1).all() and (a[:, 11:] == -2).all() and (a[:, :9] >= 0).all(), a[0]
assert b.GetNoDataValue() == -1 and b.GetDescription() == 'geodesic distance' and b.GetUnitType() == 'm'"
# The same strait drawn as a polygon (GeoJSON in WGS 84, as RFC 7946 has it) on flat land.
$PY - "$tmp" <<'PY'
import json, sys
from osgeo import osr
a = osr.SpatialReference(); a.ImportFromEPSG(32633)
b = osr.SpatialReference(); b.ImportFromEPSG(4326); b.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
t = osr.CoordinateTransformation(a, b)
ring = [t.TransformPoint(x, y)[:2] for x, y in
        [(500088, 5000050), (500112, 5000050), (500112, 4999850), (500088, 4999850), (500088, 5000050)]]
json.dump({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {},
           "geometry": {"type": "Polygon", "coordinates": [ring]}}]}, open(f"{sys.argv[1]}/wall.geojson", "w"))
PY
"$GEODEX" info "$tmp/strait.tif" --barrier "$tmp/wall.geojson" --format json >"$tmp/bw.json"
check "barrier polygons: faces counted" $PY -c "
import json; d = json.load(open('$tmp/bw.json')); assert d['barrier_faces'] == 3 * 2 * 9, d['barrier_faces']  # centres in x 500088-500112: 3 blocks a row"
"$GEODEX" distances "$tmp/strait.tif" --sources g:500005:4999995 --barrier "$tmp/wall.geojson" >"$tmp/bw.txt"
check "barrier polygons: beyond is inf" $PY -c "
import math; d = [float(x) for x in open('$tmp/bw.txt')]
assert len(d) >= 200 and math.isinf(d[15]) and math.isfinite(d[5]), (d[5], d[15])"
"$GEODEX" distances "$tmp/strait.tif" --sources g:500005:4999995 >"$tmp/nb.txt"
# Lines are walls --barrier-width wide: a fence across the whole DEM separates (and says the
# surface is in 2 parts), the same fence with a 20 m gap lets paths through it, longer than the
# straight line; a line without a width is refused; a polygon that misses the DEM is said.
crs='"crs": {"type": "name", "properties": {"name": "EPSG:32633"}}'
echo "{\"type\": \"FeatureCollection\", $crs, \"features\": [{\"type\": \"Feature\", \"properties\": {}, \"geometry\": {\"type\": \"LineString\", \"coordinates\": [[500152, 5000050], [500152, 4999850]]}}]}" >"$tmp/fence.geojson"
echo "{\"type\": \"FeatureCollection\", $crs, \"features\": [{\"type\": \"Feature\", \"properties\": {}, \"geometry\": {\"type\": \"MultiLineString\", \"coordinates\": [[[500152, 5000050], [500152, 4999950]], [[500152, 4999930], [500152, 4999850]]]}}]}" >"$tmp/gap.geojson"
"$GEODEX" distances "$tmp/strait.tif" --sources g:500005:4999995 --barrier "$tmp/fence.geojson" --barrier-width 4 \
  >"$tmp/fence.txt" 2>"$tmp/fence.err"
check "line barrier: exit 0" test $? -eq 0
check "line barrier: the surface is in 2 parts, said" grep -q "the surface is in 2 parts" "$tmp/fence.err"
"$GEODEX" distances "$tmp/strait.tif" --sources g:500005:4999995 --barrier "$tmp/gap.geojson" --barrier-width 4 \
  >"$tmp/gap.txt"
check "line barrier: a fence separates, a gap lets paths through, around" $PY - "$tmp" <<'PY'
import math, sys
t = sys.argv[1]
fence = [float(x) for x in open(f"{t}/fence.txt")]
gap = [float(x) for x in open(f"{t}/gap.txt")]
plain = [float(x) for x in open(f"{t}/nb.txt")]
assert math.isinf(fence[15]) and math.isfinite(fence[5]), (fence[5], fence[15])
assert math.isfinite(gap[15]) and gap[15] > plain[15] + 1, (gap[15], plain[15])
assert abs(gap[5] - plain[5]) < 1e-9, (gap[5], plain[5])
PY
"$GEODEX" distances "$tmp/strait.tif" --sources g:500005:4999995 --barrier "$tmp/fence.geojson" >"$tmp/slit.txt" 2>/dev/null
check "line barrier without a width: a slit, it separates" $PY -c "
import math; d = [float(x) for x in open('$tmp/slit.txt')]
assert math.isinf(d[15]) and math.isfinite(d[5]) and abs(d[5] - 50) < 1e-9, (d[5], d[15])"
echo '{"type": "MultiPoint", "coordinates": [[15, 45]]}' >"$tmp/points.geojson"
"$GEODEX" distances "$tmp/strait.tif" --sources 0 --barrier "$tmp/points.geojson" 2>"$tmp/err.txt" >/dev/null
check "point barrier without a width: refused" test $? -ne 0
check "point barrier without a width: says so" grep -q "points are barriers with a width" "$tmp/err.txt"
echo '{"type": "Polygon", "coordinates": [[[-84.3, 36.6], [-84.2, 36.6], [-84.2, 36.7], [-84.3, 36.6]]]}' >"$tmp/far.geojson"
"$GEODEX" info "$tmp/strait.tif" --barrier "$tmp/far.geojson" >/dev/null 2>"$tmp/err.txt"
check "a barrier that misses: exit 0" test $? -eq 0
check "a barrier that misses: said" grep -q "cuts nothing" "$tmp/err.txt"

# On a mesh file, --barrier's polygons are in the mesh's own x y: the unit square's upper-left
# triangle (centre (1/3, 2/3)) goes, and its corner vertex 3 is unreachable.
printf 'OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n' >"$tmp/sq.off"
echo '{"type": "Polygon", "coordinates": [[[0, 0.5], [0.5, 0.5], [0.5, 1], [0, 1], [0, 0.5]]]}' \
  >"$tmp/corner.geojson"
"$GEODEX" distances "$tmp/sq.off" --sources 0 --barrier "$tmp/corner.geojson" >"$tmp/sq.txt"
check "barrier polygons on a mesh: exit 0" test $? -eq 0
check "barrier polygons on a mesh: the corner is cut off" $PY -c "
import math; d = [float(x) for x in open('$tmp/sq.txt')]
assert d[:3] == [0, 1, math.sqrt(2)] and math.isinf(d[3]), d"
"$GEODEX" distances "$tmp/strait.tif" --sources g:500005:4999995 >"$tmp/nb.txt"
check "no barrier: the sea is crossed" $PY -c "
import math; d = [float(x) for x in open('$tmp/nb.txt')]; assert len(d) == 200 and all(map(math.isfinite, d))"

# GeoJSON (RFC 7946): isochrone polygons, Voronoi cells, Delaunay and path lines, points; checked
# with a real parser (json) and shapely: every polygon valid, rings right-hand, cells that tile the
# surface without overlap (measured in the DEM's own CRS, metres, with --crs native).
P="$tmp/pond.tif"
"$GEODEX" isolines "$P" --sources g:500055:4999795 --levels 60,150,400 --output "$tmp/iso.geojson"
check "isochrones: exit 0" test $? -eq 0
"$GEODEX" isolines "$P" --sources g:500055:4999795 --levels 60,150,400 --output "$tmp/iso_native.geojson" --crs native
"$GEODEX" voronoi "$P" --sites g:500055:4999795,g:500355:4999955,g:500305:4999655 --output "$tmp/vor.geojson" --crs native
check "voronoi geojson: exit 0" test $? -eq 0
"$GEODEX" delaunay "$P" --sites g:500055:4999795,g:500355:4999955,g:500305:4999655 --output "$tmp/del.geojson"
check "delaunay geojson: exit 0" test $? -eq 0
"$GEODEX" path "$P" --from g:500055:4999795 --to g:500355:4999795 --output "$tmp/path.geojson"
check "path geojson: exit 0" test $? -eq 0
"$GEODEX" path "$P" --from g:500055:4999795 --to g:500355:4999795 >"$tmp/path.txt"
"$GEODEX" distances "$P" --sources g:500055:4999795 --at g:500355:4999795,g:500005:4999995 \
  --output "$tmp/at.geojson"
check "points geojson: exit 0" test $? -eq 0
"$GEODEX" distances "$P" --sources g:500055:4999795 --at g:500355:4999795,g:500005:4999995 >"$tmp/at.txt"
"$GEODEX" distances "$P" --sources g:500055:4999795 --at g:500355:4999795,g:500065:4999795 \
  --max-distance 50 --output "$tmp/at_null.geojson"
check "points geojson: unreachable is null, not missing" $PY -c "
import json; f = json.load(open('$tmp/at_null.geojson'))['features']
p = [x['properties'] for x in f]
assert p[0]['distance'] is None and p[0]['source'] is None and 'distance' in p[0], p[0]
assert abs(p[1]['distance'] - 10) < 1e-9 and p[1]['source'] == 0, p[1]"
"$GEODEX" info "$P" --format json >"$tmp/pond.json"
check "geojson: valid, right-hand, isochrones with the pond as a hole, cells tiling the surface" \
  $PY - "$tmp" <<'PY'
import json, math, sys
from shapely.geometry import shape
from shapely.geometry.polygon import orient
t = sys.argv[1]
load = lambda n: json.load(open(f"{t}/{n}.geojson"))
def polygons(g):
    return list(g.geoms) if g.geom_type == "MultiPolygon" else [g]
for name in ("iso", "vor", "del", "path", "at", "iso_native"):
    d = load(name)
    assert d["type"] == "FeatureCollection" and d["features"], name
    assert ("crs" in d) == (name in ("vor", "iso_native")), name  # --crs native says so
iso = load("iso")["features"]
assert [f["properties"]["level"] for f in iso] == [60, 150, 400]
assert all(f["properties"]["units"] == "m" for f in iso)
for f in iso:
    g = shape(f["geometry"])
    assert g.is_valid and g.geom_type in ("Polygon", "MultiPolygon"), f["properties"]
    for p in polygons(g):  # RFC 7946: exterior counter-clockwise, holes clockwise
        assert p.exterior.is_ccw and all(not r.is_ccw for r in p.interiors)
    lon, lat = g.representative_point().coords[0]
    assert 14.9 < lon < 15.1 and 45.1 < lat < 45.2, (lon, lat)  # WGS 84 degrees
native = [shape(f["geometry"]) for f in load("iso_native")["features"]]
# Level 60 is a disc around the source (piecewise linear: a little inside the circle).
assert 0.95 * math.pi * 60**2 < native[0].area <= math.pi * 60**2 * 1.001, native[0].area
# Level 400 reaches around the pond: the pond is a hole in it, the rest of the map inside.
big = native[2]
assert big.geom_type == "Polygon" and len(big.interiors) == 1, big.geom_type
land = json.load(open(f"{t}/pond.json"))["faces"] * 50  # each face half a 10 m cell
assert abs(big.area - land) < 1e-6 * land, (big.area, land)
cells = [shape(f["geometry"]) for f in load("vor")["features"]]
assert [f["properties"]["site"] for f in load("vor")["features"]] == [0, 1, 2]
assert all(c.is_valid for c in cells)
total = sum(c.area for c in cells)
assert abs(total - land) < 1e-6 * land, (total, land)
for i in range(3):
    for j in range(i + 1, 3):
        assert cells[i].intersection(cells[j]).area < 1e-6 * land
lines = load("del")["features"]
assert len(lines) == 3 and all(f["geometry"]["type"] == "LineString" for f in lines)
path = load("path")["features"][0]
want = float(open(f"{t}/path.txt").readline())
assert path["geometry"]["type"] == "LineString" and len(path["geometry"]["coordinates"][0]) == 3
assert abs(path["properties"]["length"] - want) <= 1e-12 * want and want > 300  # around the pond
pts = load("at")["features"]
exact = [float(l.split("\t")[2].split()[1]) for l in open(f"{t}/at.txt")]
assert [f["properties"]["distance"] for f in pts] == exact, (pts, exact)
assert [f["properties"]["point"] for f in pts] == ["g:500355:4999795", "g:500005:4999995"]
assert all(f["properties"]["surface_point"].startswith("f:") for f in pts)
PY
"$GEODEX" isolines "$tmp/tri.off" --sources 0 --count 3 --output "$tmp/x.geojson" 2>"$tmp/err.txt"
check "geojson from a mesh: exit 2" test $? -eq 2
check "geojson from a mesh: says why" grep -q "a GIS file needs a DEM" "$tmp/err.txt"

# --labels-output beside a text --output: both written.
"$GEODEX" distances "$tmp/slot.tif" --sources g:500105:4999845 --labels-output "$tmp/n2.tif" \
  --output "$tmp/d2.txt"
check "labels raster beside text distances" test "$(wc -l <"$tmp/d2.txt")" -eq 850

# Remotely, `mesh upload DEM` sends the GeoTIFF itself: geodexd makes the same mesh and keeps its
# map, so a query by the mesh's name needs no file here, map points, rasters and GeoJSON included.
if [ "${GEODEX_MODE:-local}" = remote ]; then
  "$GEODEX" mesh upload "$tmp/slot.tif" --name slot >"$tmp/up.txt"
  check "mesh upload DEM: exit 0" test $? -eq 0
  check "mesh upload DEM: its mesh" grep -q "slot	850 vertices" "$tmp/up.txt"
  "$GEODEX" distances slot --sources 0 >"$tmp/byname.txt"
  "$GEODEX" distances "$tmp/slot.tif" --sources 0 >"$tmp/bypath.txt"
  check "mesh upload DEM: by name = by path" cmp -s "$tmp/byname.txt" "$tmp/bypath.txt"
  "$GEODEX" info slot >"$tmp/info-name.txt"
  check "info by name: the raster's CRS" grep -q "^crs: .*UTM zone 33N" "$tmp/info-name.txt"
  check "info by name: the nodata count" grep -q "^nodata_cells: 50$" "$tmp/info-name.txt"
  "$GEODEX" distances slot --sources g:500105:4999845 --at ll:15.0026:45.1522,g:500205:4999845 \
    >"$tmp/at-name.txt"
  "$GEODEX" distances "$tmp/slot.tif" --sources g:500105:4999845 \
    --at ll:15.0026:45.1522,g:500205:4999845 >"$tmp/at-path.txt"
  check "map points by name = by path" cmp -s "$tmp/at-name.txt" "$tmp/at-path.txt"
  check "map points by name: answered" test "$(wc -l <"$tmp/at-name.txt")" -ge 2
  "$GEODEX" distances slot --sources g:500105:4999845 --output "$tmp/byname.tif"
  check "raster by name: exit 0" test $? -eq 0
  "$GEODEX" isolines slot --sources g:500105:4999845 --levels 100,200 --output "$tmp/byname.geojson"
  check "geojson by name: exit 0" test $? -eq 0
  check "geojson by name: two isochrones" test "$($PY -c "import json,sys; print(len(json.load(open(sys.argv[1]))['features']))" "$tmp/byname.geojson")" -eq 2
  "$GEODEX" distances slot --sources g:500148:4999800 2>"$tmp/err.txt" >/dev/null
  check "by name, in the slot: named" grep -q -- "--sources: point g:500148:4999800: in a hole of the DEM" "$tmp/err.txt"
  # Barriers on a mesh named on the server: geodexd derives the mesh (DeriveMesh). The strait's
  # wall gives the mesh --barrier gives by path (the same answers); below a height, faces go.
  "$GEODEX" mesh upload "$tmp/strait.tif" --name strait >/dev/null
  "$GEODEX" distances strait --sources g:500005:4999995 --barrier "$tmp/wall.geojson" >"$tmp/bw-name.txt"
  check "barrier by name: exit 0" test $? -eq 0
  check "barrier by name = by path" cmp -s "$tmp/bw-name.txt" "$tmp/bw.txt"
  "$GEODEX" mesh upload "$tmp/sq.off" --name sq >/dev/null
  "$GEODEX" distances sq --sources 0 --barrier "$tmp/corner.geojson" >"$tmp/sq-name.txt"
  check "barrier polygons on a mesh by name = by path" cmp -s "$tmp/sq-name.txt" "$tmp/sq.txt"
  "$GEODEX" distances strait --sources g:500005:4999995 --barrier-below 0 >"$tmp/b-name.txt"
  check "barrier below by name: the far shore inf" $PY - "$tmp/b-name.txt" <<'PY'
import math, sys
d = [float(x) for x in open(sys.argv[1])]
assert len(d) == 200 and math.isfinite(d[0]) and math.isinf(d[19]), (len(d), d[0], d[19])
PY
  echo '{"type": "Point", "coordinates": [15, 45]}' >"$tmp/point.geojson"
  "$GEODEX" distances strait --sources 0 --barrier "$tmp/point.geojson" 2>"$tmp/err.txt" >/dev/null
  check "bad barrier by name: exit 3" test $? -eq 3
  check "bad barrier by name: names the flag" grep -q -- "--barrier $tmp/point.geojson: .*points are barriers with a width" "$tmp/err.txt"
fi

# geodex never reaches out (issue 30): a listener on a port the kernel picks counts connections
# while the CLI reads GeoJSON whose "crs" links to it or names it, a VRT whose source is on it, and
# a NAD27 DEM with PROJ's network switched on by the environment and pointed at it. Each input
# is refused (or, for the DEM, read with the grids on this machine) and nothing connects.
$PY - "$tmp" <<'PY' &
import socket, sys, time
out = sys.argv[1]
srv = socket.socket(); srv.bind(("127.0.0.1", 0)); srv.listen(16); srv.settimeout(0.2)
open(f"{out}/listener.count", "w").write("0")
open(f"{out}/listener.port.tmp", "w").write(str(srv.getsockname()[1]))
import os; os.rename(f"{out}/listener.port.tmp", f"{out}/listener.port")
n, end = 0, time.time() + 120  # bounded: it stops by itself
while time.time() < end and not os.path.exists(f"{out}/listener.stop"):
    try:
        c, _ = srv.accept(); n += 1; c.close(); open(f"{out}/listener.count", "w").write(str(n))
    except socket.timeout:
        pass
PY
listener_pid=$!
for _ in $(seq 100); do [ -s "$tmp/listener.port" ] && break; sleep 0.1; done
url="http://127.0.0.1:$(cat "$tmp/listener.port")"
ring='[[[500088, 5000050], [500112, 5000050], [500112, 4999850], [500088, 5000050]]]'
for crs in "{\"type\": \"link\", \"properties\": {\"href\": \"$url/crs\"}}" \
           "{\"type\": \"name\", \"properties\": {\"name\": \"$url/crs\"}}"; do
  echo "{\"type\": \"FeatureCollection\", \"crs\": $crs, \"features\": [{\"type\": \"Feature\", \"properties\": {}, \"geometry\": {\"type\": \"Polygon\", \"coordinates\": $ring}}]}" >"$tmp/linked.geojson"
  start=$(date +%s)
  "$GEODEX" info "$tmp/strait.tif" --barrier "$tmp/linked.geojson" 2>"$tmp/err.txt" >/dev/null
  code=$?
  check "crs link or URL name: refused (exit $code)" test "$code" -ne 0
  check "crs link or URL name: says why" grep -q 'reads no URL or file that its input names' "$tmp/err.txt"
  check "crs link or URL name: quickly" test $(( $(date +%s) - start )) -lt 5
done
printf '<VRTDataset rasterXSize="10" rasterYSize="10"><SRS>EPSG:32633</SRS><GeoTransform>500000,10,0,5000000,0,-10</GeoTransform><VRTRasterBand dataType="Float32" band="1"><SimpleSource><SourceFilename>/vsicurl/%s/src.tif</SourceFilename><SourceBand>1</SourceBand></SimpleSource></VRTRasterBand></VRTDataset>\n' "$url" >"$tmp/remote.vrt"
"$GEODEX" info "$tmp/remote.vrt" 2>"$tmp/err.txt" >/dev/null
check "VRT with a network source: refused" test $? -ne 0
check "VRT: says why" grep -q "a VRT is not read (its sources may name other files or URLs)" "$tmp/err.txt"
$PY - "$tmp" <<'PY'
import sys
import numpy as np
from osgeo import gdal, osr
ds = gdal.GetDriverByName("GTiff").Create(f"{sys.argv[1]}/nad27.tif", 20, 20, 1, gdal.GDT_Float32)
ds.SetGeoTransform((-84.31, 0.001, 0, 36.61, 0, -0.001))
s = osr.SpatialReference(); s.ImportFromEPSG(4267); ds.SetProjection(s.ExportToWkt())
ds.GetRasterBand(1).WriteArray(np.zeros((20, 20)))
ds = None
PY
PROJ_NETWORK=ON PROJ_NETWORK_ENDPOINT="$url" "$GEODEX" info "$tmp/nad27.tif" >"$tmp/nad27.txt" 2>"$tmp/err.txt"
check "NAD27 DEM with PROJ_NETWORK=ON: read offline" test $? -eq 0
touch "$tmp/listener.stop"
wait "$listener_pid"
check "nothing connected to the listener" test "$(cat "$tmp/listener.count")" = 0

# GIS files by extension (terrain/src/gis_formats.cc): rasters .asc and .nc hold the GeoTIFF's
# values; isochrones as GeoPackage, Shapefile and FlatGeobuf are the native GeoJSON's polygons in
# the DEM's CRS; an extension that is not a vector file's is refused, naming those that are.
"$GEODEX" distances "$P" --sources g:500055:4999795 --output "$tmp/pd.tif" --labels-output "$tmp/pl.asc"
"$GEODEX" distances "$P" --sources g:500055:4999795 --output "$tmp/pd.asc"
"$GEODEX" distances "$P" --sources g:500055:4999795 --output "$tmp/pd.nc"
for ext in gpkg shp fgb; do
  "$GEODEX" isolines "$P" --sources g:500055:4999795 --levels 60,150,400 --output "$tmp/iso.$ext"
done
check "GIS files: rasters and vectors read back by GDAL/OGR" $PY - "$tmp" <<'PY'
import json, sys
import numpy as np
from osgeo import gdal, ogr, osr
from shapely import wkb
from shapely.geometry import shape
gdal.UseExceptions()
t = sys.argv[1]
tif = gdal.Open(f"{t}/pd.tif").ReadAsArray()
for ext, tol in (("asc", 1e-3), ("nc", 0)):
    d = gdal.Open(f"{t}/pd.{ext}")
    a = d.ReadAsArray()
    assert a.shape == tif.shape, (ext, a.shape)
    assert np.allclose(a, tif, atol=tol, rtol=0), (ext, np.abs(a - tif).max())
    assert d.GetGeoTransform() == gdal.Open(f"{t}/pd.tif").GetGeoTransform(), ext
    assert (a == -1).sum() == 100 and d.GetRasterBand(1).GetNoDataValue() == -1, ext  # the pond
labels = gdal.Open(f"{t}/pl.asc").ReadAsArray()
assert ((labels == 0) | (labels == -1)).all() and (labels == -1).sum() == 100
native = [shape(f["geometry"]) for f in json.load(open(f"{t}/iso_native.geojson"))["features"]]
for ext in ("gpkg", "shp", "fgb"):
    ds = ogr.Open(f"{t}/iso.{ext}")
    layer = ds.GetLayer(0)
    assert layer.GetSpatialRef().GetAuthorityCode(None) == "32633", ext
    polygons = [wkb.loads(bytes(f.GetGeometryRef().ExportToWkb())) for f in layer]
    assert len(polygons) == 3, (ext, len(polygons))
    for p, q in zip(polygons, native):
        assert p.geom_type in ("Polygon", "MultiPolygon") and abs(p.area - q.area) < 1e-6 * q.area, (ext, p.area, q.area)
PY
"$GEODEX" isolines "$P" --sources g:500055:4999795 --levels 60 --output "$tmp/iso.kml" 2>"$tmp/err.txt" >/dev/null
check "unknown vector extension: exit 2" test $? -eq 2
check "unknown vector extension: names the supported ones" grep -q ".geojson, .gpkg, .shp, .fgb" "$tmp/err.txt"
"$GEODEX" distances "$P" --sources g:500055:4999795 --output "$tmp/pd.img" 2>"$tmp/err.txt" >/dev/null
check "a GIS raster extension geodex does not write: exit 2" test $? -eq 2
check "a GIS raster extension geodex does not write: names the supported ones" grep -q "rasters: .tif, .tiff, .asc, .nc" "$tmp/err.txt"

# Messages in map terms: a point outside the DEM gets the DEM's extent in its own coordinates and
# a hint when its coordinates swapped would be inside; an unreachable point is quoted as written,
# with the reason; locate drops g: and ll: points.
"$GEODEX" distances "$tmp/plane.tif" --sources g:4999722.2:500301.9 2>"$tmp/err.txt" >/dev/null
check "outside: the DEM's extent" grep -q "it covers x 500005 to 500395, y 4999705 to 4999995 in WGS 84 / UTM zone 33N" "$tmp/err.txt"
check "outside: x and y swapped" grep -q "g:500301.9:4999722.2 would be inside (x and y swapped?)" "$tmp/err.txt"
swapped=$(echo "$ll" | awk -F: '{print "ll:" $3 ":" $2}')
"$GEODEX" distances "$tmp/plane.tif" --sources "$swapped" 2>"$tmp/err.txt" >/dev/null
check "outside: longitude and latitude extent" grep -q "it covers longitude 15.0000[0-9]* to 15.00[0-9]*, latitude 45.1" "$tmp/err.txt"
check "outside: longitude and latitude swapped" grep -q "would be inside (longitude first: ll:LON:LAT)" "$tmp/err.txt"
"$GEODEX" path "$tmp/strait.tif" --from g:500005:4999995 --to g:500195.0:4999995 --barrier-below 0 \
  2>"$tmp/err.txt" >/dev/null
check "unreachable: exit 1" test $? -eq 1
check "unreachable: quoted as written, with why" grep -q "g:500195.0:4999995 is unreachable from g:500005:4999995: it is on another part of the surface" "$tmp/err.txt"
"$GEODEX" locate "$tmp/plane.tif" --points "g:500013.3:4999981.7,$ll,p:500100:4999900:100" --format json >"$tmp/loc.json"
check "locate: g: and ll: points dropped, p: snapped" $PY - "$tmp/loc.json" "$ll" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))["points"]
z = lambda x, y: 0.1 * (x - 500000) + 0.2 * (y - 4999700)
assert [p["query"] for p in d] == ["g:500013.3:4999981.7", sys.argv[2], "p:500100:4999900:100"], d
x, y, h = d[0]["p"]
assert abs(x - 500013.3) < 1e-6 and abs(y - 4999981.7) < 1e-6 and abs(h - z(x, y)) < 1e-6 and d[0]["snap_distance"] == 0
x, y, h = d[1]["p"]
assert abs(x - 500301.9) < 1e-3 and abs(y - 4999722.2) < 1e-3 and abs(h - z(x, y)) < 1e-6
assert d[2]["snap_distance"] > 0
PY

# Points from files: the same two sources from GeoJSON (WGS 84), GeoPackage (UTM 33N), Shapefile
# (WGS 84), FlatGeobuf (UTM) and CSV (x,y in the DEM's CRS; lon,lat) give the same field as the
# sources written out; --targets-file feeds a matrix; a point outside is named as the file's feature.
$PY - "$tmp" <<'PY'
import sys
from osgeo import gdal, ogr, osr
gdal.UseExceptions()
t = sys.argv[1]
utm = osr.SpatialReference(); utm.ImportFromEPSG(32633)
wgs = osr.SpatialReference(); wgs.ImportFromEPSG(4326); wgs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
to_ll = osr.CoordinateTransformation(utm, wgs)
pts = [(500013.3, 4999981.7), (500301.9, 4999722.2)]
ll = [to_ll.TransformPoint(x, y)[:2] for x, y in pts]
def write(name, driver, srs, coords):
    ds = ogr.GetDriverByName(driver).CreateDataSource(f"{t}/{name}")
    layer = ds.CreateLayer("p", srs, ogr.wkbPoint)
    for x, y in coords:
        f = ogr.Feature(layer.GetLayerDefn()); g = ogr.Geometry(ogr.wkbPoint); g.AddPoint_2D(x, y); f.SetGeometry(g); layer.CreateFeature(f)
    ds = None
write("pts.geojson", "GeoJSON", wgs, ll)
write("pts.gpkg", "GPKG", utm, pts)
write("pts.shp", "ESRI Shapefile", wgs, ll)
write("pts.fgb", "FlatGeobuf", utm, pts)
open(f"{t}/xy.csv", "w").write("name,x,y\n" + "".join(f"p{i},{x!r},{y!r}\n" for i, (x, y) in enumerate(pts)))
open(f"{t}/ll.csv", "w").write("lon,lat\n" + "".join(f"{x!r},{y!r}\n" for x, y in ll))
open(f"{t}/far.csv", "w").write("x,y\n500013.3,4999981.7\n400000,4999981.7\n")
PY
"$GEODEX" distances "$tmp/plane.tif" --sources g:500013.3:4999981.7,g:500301.9:4999722.2 >"$tmp/two.txt"
for f in pts.geojson pts.gpkg pts.shp pts.fgb xy.csv ll.csv; do
  "$GEODEX" distances "$tmp/plane.tif" --sources-file "$tmp/$f" >"$tmp/file.txt" 2>"$tmp/err.txt"
  check "--sources-file $f: exit 0" test $? -eq 0
  check "--sources-file $f: the field of the points written out (within 1e-6 m)" $PY -c "
a = [float(x) for x in open('$tmp/two.txt')]; b = [float(x) for x in open('$tmp/file.txt')]
assert len(a) == len(b) and max(abs(x - y) for x, y in zip(a, b)) < 1e-6, max(abs(x - y) for x, y in zip(a, b))"
done
"$GEODEX" matrix "$tmp/plane.tif" --sources g:500100:4999900 --targets-file "$tmp/pts.gpkg" >"$tmp/m.txt"
check "--targets-file: a matrix row of two" $PY -c "
r = open('$tmp/m.txt').read().split(); assert len(r) == 2 and all(float(x) > 0 for x in r), r"
"$GEODEX" distances "$tmp/plane.tif" --sources-file "$tmp/far.csv" 2>"$tmp/err.txt" >/dev/null
check "--sources-file: a point outside: exit 2" test $? -eq 2
check "--sources-file: a point outside is the file's feature" grep -q -- "--sources-file $tmp/far.csv feature 2 at g:400000:4999981.7: outside the DEM" "$tmp/err.txt"
"$GEODEX" info "$tmp/plane.tif" --targets-file "$tmp/pts.gpkg" 2>"$tmp/err.txt" >/dev/null
check "--targets-file where there are no targets: named" grep -q "unknown option --targets-file" "$tmp/err.txt"

# A DEM's picture has a scale bar: a dark run at the bottom left, as long as a round length at
# the picture's scale (the cell centres span 390 m; the top view frames them in 90% of 688 px, so
# 100 m is 688 * 0.9 / 390 * 100 = 159 px).
"$GEODEX" render "$tmp/plane.tif" --sources g:500013.3:4999981.7 --view top --levels 100,200 --output "$tmp/plane.png"
check "render a DEM: exit 0" test $? -eq 0
check "render a DEM: a scale bar of a round length" $PY - "$tmp/plane.png" "$(dirname "$0")/png_probe.py" <<'PY'
import importlib.util, sys
spec = importlib.util.spec_from_file_location("probe", sys.argv[2]); probe = importlib.util.module_from_spec(spec); spec.loader.exec_module(probe)
w, h, rows = probe.read_png(sys.argv[1])
y = h - 13
run = 0
while rows[y][3 * (12 + run):3 * (12 + run) + 3] == bytes([30, 30, 30]):
    run += 1
assert abs(run - 688 * 0.9 / 390 * 100) <= 2, run
PY

# An adaptive TIN (--z-tolerance): the plane is two triangles, its raster the exact plane distance
# at every cell; the slot is cut out along the grid's boundary (the same nodata cells); info says Z
# and the deviation; a bad Z is named. In remote mode the GeoTIFF goes up with Z (the same TIN).
"$GEODEX" info "$tmp/plane.tif" --z-tolerance 0.5 --format json >"$tmp/tin.json"
check "tin info: exit 0" test $? -eq 0
check "tin info: 4 vertices, 2 faces, Z, deviation" $PY -c "
import json; d = json.load(open('$tmp/tin.json'))
assert d['vertices'] == 4 and d['faces'] == 2 and d['z_tolerance'] == 0.5, d
assert d['max_vertical_deviation'] < 1e-9, d"
"$GEODEX" distances "$tmp/plane.tif" --z-tolerance 0.5 --sources g:500013.3:4999981.7 \
  --output "$tmp/tin.tif"
check "tin raster: exit 0" test $? -eq 0
check "tin raster: the plane's straight distance at every cell" $PY - "$tmp/tin.tif" <<'PY'
import math, sys
import numpy as np
from osgeo import gdal
a = gdal.Open(sys.argv[1]).ReadAsArray().astype(float)
z = lambda x, y: 0.1 * (x - 500000) + 0.2 * (y - 4999700)
s = (500013.3, 4999981.7)
worst = 0
for j in range(30):
    for i in range(40):
        x, y = 500000 + (i + 0.5) * 10, 5000000 - (j + 0.5) * 10
        want = math.dist((*s, z(*s)), (x, y, z(x, y)))
        worst = max(worst, abs(a[j, i] - want) / want)
assert worst < 1e-6, worst   # float32 cells
PY
"$GEODEX" distances "$tmp/slot.tif" --sources g:500105:4999845 --output "$tmp/grid-slot.tif"
"$GEODEX" distances "$tmp/slot.tif" --z-tolerance 0.1 --sources g:500105:4999845 \
  --output "$tmp/tin-slot.tif"
check "tin slot: the grid's holes and distances" $PY - "$tmp/grid-slot.tif" "$tmp/tin-slot.tif" <<'PY'
import sys
import numpy as np
from osgeo import gdal
a = gdal.Open(sys.argv[1]).ReadAsArray().astype(float)
b = gdal.Open(sys.argv[2]).ReadAsArray().astype(float)
assert ((a == -1) == (b == -1)).all() and (a == -1).sum() == 50
m = a >= 0
assert np.abs(a[m] - b[m]).max() <= 1e-6 * a[m].max(), np.abs(a[m] - b[m]).max()
PY
"$GEODEX" info "$tmp/plane.tif" --z-tolerance -1 2>"$tmp/err.txt" >/dev/null
check "bad Z: exit 2" test $? -eq 2
check "bad Z: named" grep -q -- "--z-tolerance" "$tmp/err.txt"
"$GEODEX" info "$tmp/tri.off" --z-tolerance 1 2>"$tmp/err.txt" >/dev/null
check "Z on a mesh: exit 2" test $? -eq 2

# Errors: map points need a DEM, a point outside or in the slot is named, --dem-step needs a DEM.
"$GEODEX" distances "$tmp/tri.off" --sources g:1:2 2>"$tmp/err.txt" >/dev/null
check "g: on a mesh: exit 2" test $? -eq 2
check "g: on a mesh: says why" grep -q "map coordinates need a DEM" "$tmp/err.txt"
"$GEODEX" distances "$tmp/slot.tif" --sources g:400000:4999845 2>"$tmp/err.txt" >/dev/null
check "outside: exit 2" test $? -eq 2
check "outside: names the point" grep -q -- "--sources: point g:400000:4999845: outside the DEM" "$tmp/err.txt"
"$GEODEX" distances "$tmp/slot.tif" --sources g:500148:4999800 2>"$tmp/err.txt" >/dev/null
check "in the slot: named" grep -q "g:500148:4999800: in a hole of the DEM" "$tmp/err.txt"
"$GEODEX" info "$tmp/tri.off" --dem-step 2 2>"$tmp/err.txt" >/dev/null
check "--dem-step on a mesh: exit 2" test $? -eq 2
"$GEODEX" distances "$tmp/tri.off" --sources 0 --output "$tmp/x.tif" 2>"$tmp/err.txt" >/dev/null
check "raster from a mesh: exit 2" test $? -eq 2
check "raster from a mesh: says why" grep -q "needs a DEM" "$tmp/err.txt"

finish "terrain cli"
