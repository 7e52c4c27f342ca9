#!/usr/bin/env bash
# The adaptive TIN (--z-tolerance) against the full grid, side by side in one run, on three DEMs:
# the smooth 1000 x 1000 hills of terrain_bench.sh (at --dem-step 2: 250k cells, and whole: 1M),
# the real Jacksboro DEM (403 x 344 cells of 74 x 93 m, from ../shared/meshes) and the same hills
# with 2 m of noise (rough terrain, where a TIN loses). Per Z: vertices, the whole command's wall
# time and peak RSS (read, TIN, solve, exact raster), load (read + TIN) and solve ms, and against
# the grid's exact field at every cell the largest and mean difference relative to the largest
# distance, and the isochrone polygons' symmetric difference (area, relative to the grid's).
# Prints markdown tables for docs/performance.md.
# usage: bench/terrain_tin_bench.sh [GEODEX] [SHARED_MESHES]
set -euo pipefail
geodex="${1:-build/client/geodex}"
shared="${2:-../shared/meshes}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 - "$tmp" "$shared/jacksboro-terrain.off.gz" <<'PY'
import gzip, os, sys
import numpy as np
from osgeo import gdal, osr
gdal.UseExceptions()
out, jacksboro = sys.argv[1], sys.argv[2]
def write(name, z, gt, epsg):
    ds = gdal.GetDriverByName("GTiff").Create(os.path.join(out, name), z.shape[1], z.shape[0], 1,
                                              gdal.GDT_Float32, ["COMPRESS=DEFLATE"])
    ds.SetGeoTransform(gt)
    s = osr.SpatialReference(); s.ImportFromEPSG(epsg); ds.SetProjection(s.ExportToWkt())
    ds.GetRasterBand(1).WriteArray(z.astype(np.float32)); ds = None
W = H = 1000
i, j = np.meshgrid(np.arange(W), np.arange(H))
z = 300 + 80 * np.sin(i / 57.0) * np.cos(j / 43.0) + 0.1 * i + 30 * np.sin(j / 200.0)
write("smooth.tif", z, (600000, 30, 0, 5100000, 0, -30), 32632)
rough = z[:500, :500] + np.random.default_rng(1).uniform(-2, 2, (500, 500))
write("rough.tif", rough, (600000, 30, 0, 5100000, 0, -30), 32632)
# Jacksboro: vertex id = row * 403 + col, x = col * 74.4, y = -row * 92.66, z in metres.
with gzip.open(jacksboro, "rt") as f:
    f.readline(); n = int(f.readline().split()[0])
    v = np.loadtxt(f, max_rows=n)
dx, dy = v[1, 0] - v[0, 0], v[0, 1] - v[403, 1]
write("jacksboro.tif", v[:, 2].reshape(-1, 403), (700000 - dx / 2, dx, 0, 4050000 + dy / 2, 0, -dy),
      32616)
PY
stat() { tr ',' '\n' <"$1" | sed -n "s/.*\"$2\": \([0-9.e+]*\).*/\1/p" | head -1; }
compare() {  # grid raster, TIN raster, grid isochrones, TIN isochrones
  /usr/bin/python3 - "$@" <<'PY'
import sys
import numpy as np
from osgeo import gdal, ogr
gdal.UseExceptions()
a = gdal.Open(sys.argv[1]).ReadAsArray().astype(float)
b = gdal.Open(sys.argv[2]).ReadAsArray().astype(float)
m = (a >= 0) & (b >= 0)
rel = np.abs(a[m] - b[m]) / a[m].max()
def union(path):
    ds = ogr.Open(path)
    geoms = [f.GetGeometryRef().Clone() for f in ds.GetLayer()]
    return geoms[0]
ga, gb = union(sys.argv[3]), union(sys.argv[4])
print("%.2g | %.2g | %.2g" % (rel.max(), rel.mean(), ga.SymDifference(gb).GetArea() / ga.GetArea()))
PY
}
for case in "smooth.tif --dem-step 2|g:615000:5085000|5000" "smooth.tif|g:615000:5085000|5000" \
            "jacksboro.tif|g:715000:4035000|8000" "rough.tif|g:607500:5092500|4000"; do
  IFS='|' read -r dem src level <<<"$case"
  echo
  echo "$dem, source $src, isochrone at $level m:"
  echo
  echo "| Z (m) | vertices | wall s | peak RSS MiB | load ms | solve ms | max rel diff | mean rel diff | isochrone sym. diff |"
  echo "|---|---|---|---|---|---|---|---|---|"
  for z in 0 0.1 0.5 2; do
    # shellcheck disable=SC2086
    /usr/bin/time -f "%e %M" -o "$tmp/time" "$geodex" distances "$tmp/"$dem --z-tolerance $z \
      --sources "$src" --output "$tmp/d$z.tif" --stats 2>"$tmp/s.json"
    read -r wall kb <"$tmp/time"
    # shellcheck disable=SC2086
    "$geodex" isolines "$tmp/"$dem --z-tolerance $z --sources "$src" --levels "$level" \
      --output "$tmp/i$z.geojson"
    diff="- | - | -"
    if [ "$z" != 0 ]; then diff=$(compare "$tmp/d0.tif" "$tmp/d$z.tif" "$tmp/i0.geojson" "$tmp/i$z.geojson"); fi
    printf "| %s | %s | %s | %.0f | %s | %s | %s |\n" "$z" "$(stat "$tmp/s.json" vertices)" "$wall" \
      "$(echo "$kb / 1024" | bc -l)" "$(stat "$tmp/s.json" load_ms)" "$(stat "$tmp/s.json" solve_ms)" "$diff"
  done
done
