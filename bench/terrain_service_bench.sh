#!/usr/bin/env bash
# Terrain through geodexd, side by side in one run on the synthetic 1000 x 1000 DEM of
# bench/terrain_bench.sh (30 m cells, UTM 32N, smooth hills): uploading the GeoTIFF (geodexd reads
# it, keeps its map) against uploading the same mesh as an OFF file (the same id, checked), with
# the bytes sent and the memory each stored mesh takes; then isochrone GeoJSON from ExportGis
# against the CLI writing it locally (--dem-step 2). Prints a markdown table for
# docs/performance.md. usage: bench/terrain_service_bench.sh [BUILD_DIR] (default build)
set -euo pipefail
build="${1:-build}"
tmp=$(mktemp -d)
"$build/server/geodexd" --listen 127.0.0.1:0 --metrics_listen "" --samples=false \
  --shutdown_grace_seconds 5 >"$tmp/server.log" 2>&1 &
pid=$!
trap 'kill -TERM $pid 2>/dev/null; wait $pid 2>/dev/null; rm -rf "$tmp"' EXIT
port=""
for _ in $(seq 1 300); do
  port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$tmp/server.log" | head -1)
  [ -n "$port" ] && break
  sleep 0.1
done
[ -n "$port" ] || { echo "geodexd did not start"; exit 1; }
PYTHONPATH="client/python:$build/python" /usr/bin/python3 - "$tmp" "127.0.0.1:$port" "$build/client/geodex" <<'PY'
import os, subprocess, sys, time
import numpy as np
from osgeo import gdal, osr
import geodex
gdal.UseExceptions()
tmp, server, cli = sys.argv[1:4]
W = H = 1000
i, j = np.meshgrid(np.arange(W), np.arange(H))
z = (300 + 80 * np.sin(i / 57.0) * np.cos(j / 43.0) + 0.1 * i + 30 * np.sin(j / 200.0)).astype(np.float32)
tif = f"{tmp}/big.tif"
ds = gdal.GetDriverByName("GTiff").Create(tif, W, H, 1, gdal.GDT_Float32, ["COMPRESS=DEFLATE"])
ds.SetGeoTransform((600000, 30, 0, 5100000, 0, -30))
s = osr.SpatialReference(); s.ImportFromEPSG(32632); ds.SetProjection(s.ExportToWkt())
ds.GetRasterBand(1).WriteArray(z); ds = None
# The same mesh as an OFF file: cell centres row by row, blocks split along a-d as geodex does.
off = f"{tmp}/big.off"
x = 600000 + (i + 0.5) * 30
y = 5100000 - (j + 0.5) * 30
with open(off, "w") as f:
    f.write(f"OFF\n{W * H} {2 * (W - 1) * (H - 1)} 0\n")
    np.savetxt(f, np.column_stack([x.ravel(), y.ravel(), z.astype(np.float64).ravel()]), fmt="%.17g")
    a = (j[:-1, :-1] * W + i[:-1, :-1]).ravel()
    b, c, d = a + 1, a + W, a + W + 1
    faces = np.empty((2 * a.size, 4), dtype=np.int64)
    faces[0::2] = np.column_stack([np.full(a.size, 3), a, c, d])
    faces[1::2] = np.column_stack([np.full(a.size, 3), a, d, b])
    np.savetxt(f, faces, fmt="%d")
rows = []
with geodex.GeodexClient(server, timeout=1200) as client:
    t0 = time.perf_counter(); dem = client.upload(tif, name="dem"); t_tif = time.perf_counter() - t0
    client.delete_mesh("meshes/dem")
    t0 = time.perf_counter(); plain = client.upload(off, name="plain"); t_off = time.perf_counter() - t0
    assert plain.name == dem.name, (plain.name, dem.name)  # the same mesh
    rows.append(("upload (1000 x 1000, 1M vertices)", f"GeoTIFF {os.path.getsize(tif) / 2**20:.1f} MiB: {t_tif:.2f} s, "
                 f"{dem.memory_bytes / 2**20:.0f} MiB stored", f"OFF {os.path.getsize(off) / 2**20:.0f} MiB: {t_off:.2f} s, "
                 f"{plain.memory_bytes / 2**20:.0f} MiB stored",
                 f"time {t_tif / t_off:.2f}x the OFF's, {os.path.getsize(off) / os.path.getsize(tif):.0f}x fewer bytes sent, "
                 f"the grid +{(dem.memory_bytes - plain.memory_bytes) / plain.memory_bytes * 100:.0f}% memory"))
    client.delete_mesh("meshes/plain")
    small = client.upload(tif, name="small", dem_step=2)
    hut = geodex.map_point(615000, 5085000)
    t0 = time.perf_counter()
    data = client.export_gis("meshes/small", "isochrones", [hut], levels=[2000, 4000, 8000])
    t_server = time.perf_counter() - t0
    t0 = time.perf_counter()
    subprocess.run([cli, "isolines", tif, "--dem-step", "2", "--sources", "g:615000:5085000", "--levels",
                    "2000,4000,8000", "--output", f"{tmp}/local.geojson"], check=True)
    t_local = time.perf_counter() - t0
    same = open(f"{tmp}/local.geojson", "rb").read() == data
    rows.append(("isochrones GeoJSON (250k vertices, 3 levels)", f"ExportGis {t_server:.2f} s (solve on the server)",
                 f"CLI locally {t_local:.2f} s (read, build, solve, write)", f"local {t_local / t_server:.2f}x the server's time, bytes identical: {same}"))
print("| what | geodexd | the other way | ratio |")
print("|---|---|---|---|")
for r in rows:
    print("| " + " | ".join(r) + " |")
PY
