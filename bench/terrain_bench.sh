#!/usr/bin/env bash
# Terrain timings, side by side in one run: a synthetic 1000 x 1000 DEM (30 m cells, UTM 32N,
# smooth hills) read through GDAL and triangulated; one exact field against Dijkstra's at
# --dem-step 4, 2 and 1; the distance raster; isochrone polygons (GeoJSON). Prints a markdown
# table for docs/performance.md. usage: bench/terrain_bench.sh [GEODEX] (default build/client/geodex)
set -euo pipefail
geodex="${1:-build/client/geodex}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 - "$tmp/big.tif" <<'PY'
import sys
import numpy as np
from osgeo import gdal, osr
gdal.UseExceptions()
W = H = 1000
i, j = np.meshgrid(np.arange(W), np.arange(H))
z = 300 + 80 * np.sin(i / 57.0) * np.cos(j / 43.0) + 0.1 * i + 30 * np.sin(j / 200.0)
ds = gdal.GetDriverByName("GTiff").Create(sys.argv[1], W, H, 1, gdal.GDT_Float32, ["COMPRESS=DEFLATE"])
ds.SetGeoTransform((600000, 30, 0, 5100000, 0, -30))
s = osr.SpatialReference(); s.ImportFromEPSG(32632); ds.SetProjection(s.ExportToWkt())
ds.GetRasterBand(1).WriteArray(z.astype(np.float32)); ds = None
PY
src=g:615000:5085000
stat() { tr ',' '\n' <"$1" | sed -n "s/.*\"$2\": \([0-9.e+]*\).*/\1/p" | head -1; }
echo "| step | vertices | load ms | build ms | exact solve ms | windows | Dijkstra solve ms | exact / Dijkstra | wall s | peak RSS MiB |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for step in 4 2 1; do
  /usr/bin/time -f "%e %M" -o "$tmp/time" "$geodex" distances "$tmp/big.tif" --dem-step $step --sources $src \
    --output "$tmp/d.tif" --stats 2>"$tmp/exact.json"
  "$geodex" distances "$tmp/big.tif" --dem-step $step --method dijkstra --sources $src \
    --output "$tmp/dj.tif" --stats 2>"$tmp/dj.json"
  read -r wall kb <"$tmp/time"
  e=$(stat "$tmp/exact.json" solve_ms); d=$(stat "$tmp/dj.json" solve_ms)
  printf "| %s | %s | %s | %s | %.0f | %s | %.1f | %.0fx | %s | %.0f |\n" "$step" \
    "$(stat "$tmp/exact.json" vertices)" "$(stat "$tmp/exact.json" load_ms)" \
    "$(stat "$tmp/exact.json" build_ms)" "$e" "$(stat "$tmp/exact.json" windows_created)" "$d" \
    "$(echo "$e / $d" | bc -l)" "$wall" "$(echo "$kb / 1024" | bc -l)"
done
for step in 2 1; do
  /usr/bin/time -f "%e %M" -o "$tmp/time" "$geodex" isolines "$tmp/big.tif" --dem-step $step \
    --sources $src --count 5 --output "$tmp/iso.geojson"
  read -r wall kb <"$tmp/time"
  echo "isolines --count 5 to GeoJSON at --dem-step $step: ${wall} s wall (solve included), peak $((kb / 1024)) MiB"
done
