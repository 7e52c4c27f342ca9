#!/usr/bin/env bash
# docs/terrain.md "Terrain and GIS", end to end: a GeoTIFF DEM to isochrone polygons (GeoJSON), a
# distance raster and a nearest-source raster (GeoTIFF), with the lake as a barrier, and a picture.
# usage: scripts/terrain_example.sh [OUTDIR]   (default /tmp/geodex-terrain; GEODEX overrides the
# binary, default build/client/geodex). tests/CMakeLists.txt runs it, so it stays runnable.
set -euo pipefail
out="${1:-/tmp/geodex-terrain}"
geodex="${GEODEX:-build/client/geodex}"
here="$(cd "$(dirname "$0")" && pwd)"
mkdir -p "$out"

/usr/bin/python3 "$here/sample_dem.py" "$out/valley.tif"        # 120 x 100 cells of 30 m, UTM 32N
"$geodex" info "$out/valley.tif" | grep -E '^(crs|grid|nodata_cells|units):'
# Isochrones from a trailhead given in longitude/latitude: 500 m to 3 km of walking on the
# surface, the lake (below 0 m) removed so that paths go around it.
"$geodex" isolines "$out/valley.tif" --sources ll:10.2963:46.0435 --levels 500,1000,2000,3000 \
  --barrier-below 0 --output "$out/isochrones.geojson"
# The distance to the nearer of two huts (the second in the DEM's own UTM coordinates), and
# which hut is nearer, as rasters aligned with the DEM.
"$geodex" distances "$out/valley.tif" --sources ll:10.2963:46.0435,g:603300:5097900 \
  --barrier-below 0 --output "$out/distance.tif" --labels-output "$out/nearest.tif"
# The walk from the trailhead to the second hut, as a 3D line.
"$geodex" path "$out/valley.tif" --from ll:10.2963:46.0435 --to g:603300:5097900 \
  --barrier-below 0 --output "$out/walk.geojson"
# A picture: the distance field from the trailhead, ten isochrones, the lake left out.
"$geodex" render "$out/valley.tif" --sources ll:10.2963:46.0435 --isolines 10 --barrier-below 0 \
  --view top --output "$out/isochrones.png"
ls "$out"
