#!/usr/bin/env bash
# docs/terrain.md "Terrain through geodexd and Python", end to end: the sample DEM uploaded to a
# geodexd as a GeoTIFF, queried by its name with map points and the lake as a barrier derived on the
# server, then the same from Python (scripts/terrain_example.py), isochrones written by the server.
# usage: scripts/terrain_service_example.sh HOST:PORT [OUTDIR]   (default /tmp/geodex-terrain;
# GEODEX overrides the binary, default build/client/geodex). A ctest runs it against its own geodexd.
set -euo pipefail
server="$1"
out="${2:-/tmp/geodex-terrain}"
geodex="${GEODEX:-build/client/geodex}"
here="$(cd "$(dirname "$0")" && pwd)"
mkdir -p "$out"
[ -f "$out/valley.tif" ] || /usr/bin/python3 "$here/sample_dem.py" "$out/valley.tif"

"$geodex" --server "$server" mesh upload "$out/valley.tif" --name valley
# By name: no file needed here; the lake (below 0 m) is a barrier geodexd derives (DeriveMesh).
"$geodex" --server "$server" distances valley --sources ll:10.2963:46.0435 \
  --at g:603300:5097900 --barrier-below 0
# Python: the geodex package from this tree (client/python) and its generated messages.
PYTHONPATH="$here/../client/python:${GEODEX_PYTHON_STUBS:-$here/../build/python}${PYTHONPATH:+:$PYTHONPATH}" \
  /usr/bin/python3 "$here/terrain_example.py" "$server" "$out"
