#!/usr/bin/env bash
# Barrier cuts on a real terrain, in one run: the Jacksboro DEM (matplotlib's sample data, 403 x 344
# cells of 74.4 x 92.7 m; from ../shared/meshes or JACKSBORO=FILE) as a GeoTIFF in UTM 16N, and
# the barriers that leaked when faces were removed by their centre: an 18 m-wide wall across the
# whole DEM, a 4 x 15 km rectangle, and a fence line 5 m wide. For each: the faces cut and removed,
# the vertices added, whether the far side is reachable (it must not be), and `geodex info` and
# `geodex distances` times with and without it. Prints a markdown table for docs/performance.md.
# usage: [BARRIER_BENCH_DIR=DIR] bench/barrier_bench.sh [GEODEX] (default build/client/geodex)
set -euo pipefail
geodex="${1:-build/client/geodex}"
jacksboro="${JACKSBORO:-$(dirname "$0")/../../shared/meshes/jacksboro-terrain.off.gz}"
# BARRIER_BENCH_DIR=DIR keeps the DEM and the barriers there (to time them again by hand).
if [ -n "${BARRIER_BENCH_DIR:-}" ]; then
  tmp="$BARRIER_BENCH_DIR"
  mkdir -p "$tmp"
else
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
fi
/usr/bin/python3 - "$jacksboro" "$tmp" <<'PY'
import gzip, json, sys
import numpy as np
from osgeo import gdal, osr
gdal.UseExceptions()
src, out = sys.argv[1], sys.argv[2]
with gzip.open(src, "rt") as f:
    assert f.readline().strip() == "OFF"
    n, _, _ = map(int, f.readline().split())
    z = np.array([float(f.readline().split()[2]) for _ in range(n)])
W, H = 403, 344
ds = gdal.GetDriverByName("GTiff").Create(f"{out}/jacksboro.tif", W, H, 1, gdal.GDT_Float32)
x0, y0, dx, dy = 700000.0, 4050000.0, 74.40117106302108, 92.66256686119314
ds.SetGeoTransform((x0, dx, 0, y0, 0, -dy))
s = osr.SpatialReference(); s.ImportFromEPSG(32616); ds.SetProjection(s.ExportToWkt())
ds.GetRasterBand(1).WriteArray(z.reshape(H, W).astype(np.float32)); ds = None
crs = {"type": "name", "properties": {"name": "EPSG:32616"}}
def write(name, geometry):
    json.dump({"type": "FeatureCollection", "crs": crs, "features": [
        {"type": "Feature", "properties": {}, "geometry": geometry}]}, open(f"{out}/{name}.geojson", "w"))
xm = x0 + 200.3 * dx  # between cell centres
write("wall18", {"type": "Polygon", "coordinates": [[[xm - 9, y0 + 100], [xm + 9, y0 + 100],
    [xm + 9 + 500, y0 - H * dy - 100], [xm - 9 + 500, y0 - H * dy - 100], [xm - 9, y0 + 100]]]})
write("rect", {"type": "Polygon", "coordinates": [[[x0 + 5013, y0 - 8007], [x0 + 9013, y0 - 8007],
    [x0 + 9013, y0 - 23007], [x0 + 5013, y0 - 23007], [x0 + 5013, y0 - 8007]]]})
write("fence", {"type": "LineString", "coordinates": [[x0 + 20001, y0 + 50], [x0 + 14007, y0 - H * dy - 50]]})
PY
dem="$tmp/jacksboro.tif"
src=g:701000:4040000  # west of every barrier
stat() { tr ',' '\n' <"$1" | sed -n "s/.*\"$2\": \([0-9.e+]*\).*/\1/p" | head -1; }
wall() { /usr/bin/time -f "%e" -o "$tmp/t" "$@" >/dev/null 2>&1; cat "$tmp/t"; }
info_plain=$(wall "$geodex" info "$dem")
"$geodex" distances "$dem" --sources $src --stats 2>"$tmp/plain.json" >"$tmp/plain.txt"
echo "| barrier | faces removed + cut | vertices added | far side | info s (plain $info_plain) | solve ms (plain $(stat "$tmp/plain.json" solve_ms)) |"
echo "|---|---|---|---|---|---|"
for b in wall18 rect fence; do
  width=()
  [ "$b" = fence ] && width=(--barrier-width 5)
  "$geodex" info "$dem" --barrier "$tmp/$b.geojson" "${width[@]}" --format json >"$tmp/info.json" 2>/dev/null
  "$geodex" distances "$dem" --sources $src --barrier "$tmp/$b.geojson" "${width[@]}" --stats \
    2>"$tmp/cut.json" >"$tmp/cut.txt"
  faces=$(stat "$tmp/info.json" barrier_faces)
  added=$(( $(stat "$tmp/info.json" vertices) - $(stat "$tmp/plain.json" vertices) ))
  # The cell at the east edge, row 170: beyond the wall and the fence, beside the rectangle.
  far=$(sed -n "$((170 * 403 + 402 + 1))p" "$tmp/cut.txt")
  printf "| %s | %s | %s | %s | %s | %.0f |\n" "$b" "$faces" "$added" "$far" \
    "$(wall "$geodex" info "$dem" --barrier "$tmp/$b.geojson" "${width[@]}")" "$(stat "$tmp/cut.json" solve_ms)"
done
