#!/usr/bin/env bash
# Travel time (--speed) side by side in one run, as a GIS user runs it, on two DEMs: the real
# Jacksboro DEM (403 x 344 cells of 74 x 93 m, from ../shared/meshes) and the smooth hills of
# terrain_bench.sh (1000 x 1000 cells of 30 m), both at --dem-step STEP (default 2) so that the
# finest epsilon fits in minutes. Per DEM:
#   * the exact geodesic field (metres) and, all weights 1 at 3.6 km/h (1 m/s), the travel field at
#     each epsilon: the whole command's wall time (ratio to the exact one) and the largest and mean
#     relative difference from the exact distances (the bound says <= epsilon, never below);
#   * with a friction map (bands of 1, 2 and 4, a raster on the DEM's grid): each epsilon against
#     the finest one, and an 8- and a 16-neighbour grid Dijkstra with the same model (r.cost's
#     moves: a move's cost is its 3D length x the mean friction of its two end cells) against the
#     finest run.
# With SPEED=tobler (environment), per DEM instead: the exact geodesic field and the Tobler field
# (--speed tobler) at each epsilon against the finest one, with wall times and their ratio to the
# exact field's, and an 8- and a 16-neighbour grid Dijkstra under Tobler (r.walk's moves: a move
# takes its 3D length / Tobler(rise / run)) against the finest run.
# Relative differences are over the cells farther than 5% of the largest time from the source.
# Prints markdown tables for docs/performance.md.
# usage: bench/travel_bench.sh [GEODEX] [SHARED_MESHES] [STEP] [EPSILONS]
#   DEMS="jacksboro:2 smooth:4" (environment) picks the DEMs and a step for each.
set -euo pipefail
geodex="${1:-build/client/geodex}"
shared="${2:-../shared/meshes}"
step="${3:-2}"
epsilons="${4:-0.1 0.03 0.01}"
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
def friction(shape):  # bands of 1, 2 and 4 crossing the map obliquely, and a friction-4 disc
    j, i = np.mgrid[0:shape[0], 0:shape[1]]
    f = 1 + (np.sin((i + 0.6 * j) / (shape[1] / 7.0)) > 0.3) + 2 * (np.cos((j - 0.3 * i) / (shape[0] / 5.0)) > 0.6)
    f[(i - shape[1] * 0.7) ** 2 + (j - shape[0] * 0.4) ** 2 < (shape[0] * 0.12) ** 2] = 4
    return np.minimum(f, 4)
W = H = 1000
i, j = np.meshgrid(np.arange(W), np.arange(H))
z = 300 + 80 * np.sin(i / 57.0) * np.cos(j / 43.0) + 0.1 * i + 30 * np.sin(j / 200.0)
gt = (600000, 30, 0, 5100000, 0, -30)
write("smooth.tif", z, gt, 32632)
write("smooth_friction.tif", friction(z.shape), gt, 32632)
with gzip.open(jacksboro, "rt") as f:
    f.readline(); n = int(f.readline().split()[0])
    v = np.loadtxt(f, max_rows=n)
dx, dy = v[1, 0] - v[0, 0], v[0, 1] - v[403, 1]
zj = v[:, 2].reshape(-1, 403)
gt = (700000 - dx / 2, dx, 0, 4050000 + dy / 2, 0, -dy)
write("jacksboro.tif", zj, gt, 32616)
write("jacksboro_friction.tif", friction(zj.shape), gt, 32616)
PY

# The source: the used grid's centre cell, as a map point.
centre() {
  /usr/bin/python3 - "$1" "$step" <<'PY'
import sys
from osgeo import gdal
ds = gdal.Open(sys.argv[1]); s = int(sys.argv[2]); gt = ds.GetGeoTransform()
w, h = (ds.RasterXSize + s - 1) // s, (ds.RasterYSize + s - 1) // s
u, v = (w // 2) * s + 0.5, (h // 2) * s + 0.5
print(f"g:{gt[0] + u * gt[1]:.6f}:{gt[3] + v * gt[5]:.6f}")
PY
}

# seconds WALL and peak KiB of a whole command into $tmp/last.time
timed() { /usr/bin/time -f "%e %M" -o "$tmp/last.time" "$@" >/dev/null; }

cat >"$tmp/grid.py" <<'PY'
import heapq, math, sys, time
import numpy as np
from osgeo import gdal
# argv: DEM, friction raster or "1" (every cell 1), the reference time raster, STEP, and
# optionally "tobler" (a move takes its 3D length / Tobler(rise / run), friction ignored).
dem, finest, s = gdal.Open(sys.argv[1]), sys.argv[3], int(sys.argv[4])
tobler = len(sys.argv) > 5 and sys.argv[5] == "tobler"
z = dem.ReadAsArray().astype(float)[::s, ::s]
f = np.ones(z.shape) if sys.argv[2] == "1" else gdal.Open(sys.argv[2]).ReadAsArray().astype(float)[::s, ::s]
gt = dem.GetGeoTransform(); cx, cy = abs(gt[1]) * s, abs(gt[5]) * s
H, W = z.shape
best = gdal.Open(finest).ReadAsArray().astype(float)
def grid(moves):
    t0 = time.time()
    inf = float("inf"); d = np.full(H * W, inf); zf = z.ravel(); ff = f.ravel()
    src = (H // 2) * W + W // 2; d[src] = 0; heap = [(0.0, src)]
    steps = [(a, b, math.hypot(a * cx, b * cy)) for a, b in moves]
    while heap:
        c, n = heapq.heappop(heap)
        if c > d[n]: continue
        r, q = divmod(n, W)
        for a, b, L in steps:
            rr, qq = r + b, q + a
            if 0 <= rr < H and 0 <= qq < W:
                m = rr * W + qq
                rise = zf[m] - zf[n]
                if tobler:
                    w = c + math.sqrt(L * L + rise * rise) * 3.6 / (6 * math.exp(-3.5 * abs(rise / L + 0.05)))
                else:
                    w = c + math.sqrt(L * L + rise * rise) * (ff[m] + ff[n]) / 2  # 1 m/s
                if w < d[m]: d[m] = w; heapq.heappush(heap, (w, m))
    return d.reshape(H, W), time.time() - t0
eight = [(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1) if (a, b) != (0, 0)]
sixteen = eight + [(a, b) for a in (-2, -1, 1, 2) for b in (-2, -1, 1, 2) if abs(a) != abs(b)]
for name, moves in (("8", eight), ("16", sixteen)):
    d, secs = grid(moves)
    ok = (best >= 0) & (best > 0.05 * best.max())
    r = d[ok] / best[ok] - 1
    what = "r.walk's" if tobler else "r.cost's"
    print(f"| grid Dijkstra, {name} neighbours ({what} moves; Python, {secs:.0f} s) | | "
          f"{r.max():.2e} (min {r.min():.2e}) | {r.mean():.2e} |")
PY

for spec in ${DEMS:-jacksboro:$step smooth:$step}; do
  dem=${spec%%:*}
  step=${spec##*:}
  D="$tmp/$dem.tif"
  src=$(centre "$D")
  echo
  echo "### $dem at --dem-step $step, source $src"
  timed "$geodex" distances "$D" --dem-step "$step" --sources "$src" --output "$tmp/exact.tif"
  read -r exact_s exact_kib <"$tmp/last.time"
  if [ "${SPEED:-constant}" = tobler ]; then
    echo
    echo "| run | wall s | x exact | peak MiB | max rel diff | mean rel diff |"
    echo "|---|---|---|---|---|---|"
    echo "| exact geodesic field (metres) | $exact_s | 1 | $((exact_kib / 1024)) | | |"
    finest=""
    for e in $epsilons; do
      finest="$e"
      timed "$geodex" distances "$D" --dem-step "$step" --sources "$src" --speed tobler \
        --cost-epsilon "$e" --output "$tmp/tob_$e.tif"
      read -r s kib <"$tmp/last.time"
      echo "$e $s $kib" >>"$tmp/tobler_times"
    done
    while read -r e s kib; do
      /usr/bin/python3 - "$tmp/tob_$e.tif" "$tmp/tob_$finest.tif" "$s" "$exact_s" "$kib" "$e" <<'PY'
import sys
import numpy as np
from osgeo import gdal
t = gdal.Open(sys.argv[1]).ReadAsArray().astype(float); f = gdal.Open(sys.argv[2]).ReadAsArray().astype(float)
ok = (f >= 0) & (t >= 0) & (f > 0.05 * f.max())
r = t[ok] / f[ok] - 1
print(f"| Tobler, epsilon {sys.argv[6]} | {sys.argv[3]} | {float(sys.argv[3]) / float(sys.argv[4]):.1f} | "
      f"{int(sys.argv[5]) // 1024} | {r.max():.2e} | {r.mean():.2e} |")
PY
    done <"$tmp/tobler_times"
    rm -f "$tmp/tobler_times"
    /usr/bin/python3 "$tmp/grid.py" "$D" 1 "$tmp/tob_$finest.tif" "$step" tobler | sed 's/| | /| | | | /'
    continue
  fi
  echo
  echo "| run | wall s | x exact | peak MiB | max rel diff | mean rel diff |"
  echo "|---|---|---|---|---|---|"
  echo "| exact geodesic field (metres) | $exact_s | 1 | $((exact_kib / 1024)) | | |"
  for e in $epsilons; do
    timed "$geodex" distances "$D" --dem-step "$step" --sources "$src" --speed constant:3.6 \
      --cost-epsilon "$e" --output "$tmp/w1_$e.tif"
    read -r s kib <"$tmp/last.time"
    /usr/bin/python3 - "$tmp/w1_$e.tif" "$tmp/exact.tif" "$s" "$exact_s" "$kib" "$e" <<'PY'
import sys
import numpy as np
from osgeo import gdal
t = gdal.Open(sys.argv[1]).ReadAsArray().astype(float); d = gdal.Open(sys.argv[2]).ReadAsArray().astype(float)
ok = (d >= 0) & (t >= 0) & (d > 0.05 * d.max())
r = t[ok] / d[ok] - 1
print(f"| weights 1, epsilon {sys.argv[6]} | {sys.argv[3]} | {float(sys.argv[3]) / float(sys.argv[4]):.1f} | "
      f"{int(sys.argv[5]) // 1024} | {r.max():.2e} | {r.mean():.2e} |")
assert r.min() > -1e-6, ("below the least time", r.min())
PY
  done
  # r.cost's moves with every friction 1 against the exact geodesic distances: the error of moving
  # in 8 or 16 fixed directions (up to 8.2% and 2.75% on a plane).
  /usr/bin/python3 "$tmp/grid.py" "$D" 1 "$tmp/exact.tif" "$step" | sed 's/^| grid/| weights 1, grid/; s/| | /| | | | /'
  echo
  echo "With the friction map (bands of 1, 2, 4): against the finest run"
  echo
  echo "| run | wall s | max rel diff | mean rel diff |"
  echo "|---|---|---|---|"
  finest=""
  for e in $epsilons; do finest="$e"; done
  for e in $epsilons; do
    timed "$geodex" distances "$D" --dem-step "$step" --sources "$src" --speed constant:3.6 \
      --cost-epsilon "$e" --friction "$tmp/${dem}_friction.tif" --output "$tmp/wf_$e.tif"
    read -r s kib <"$tmp/last.time"
    echo "$e $s" >>"$tmp/friction_times"
  done
  while read -r e s; do
    /usr/bin/python3 - "$tmp/wf_$e.tif" "$tmp/wf_$finest.tif" "$s" "$e" <<'PY'
import sys
import numpy as np
from osgeo import gdal
t = gdal.Open(sys.argv[1]).ReadAsArray().astype(float); f = gdal.Open(sys.argv[2]).ReadAsArray().astype(float)
ok = (f >= 0) & (t >= 0) & (f > 0.05 * f.max())
r = t[ok] / f[ok] - 1
print(f"| friction, epsilon {sys.argv[4]} | {sys.argv[3]} | {r.max():.2e} | {r.mean():.2e} |")
PY
  done <"$tmp/friction_times"
  rm -f "$tmp/friction_times"
  # r.cost's moves on the same used grid (every STEP-th cell), the same model: 8 and 16 neighbours.
  /usr/bin/python3 "$tmp/grid.py" "$D" "$tmp/${dem}_friction.tif" "$tmp/wf_$finest.tif" "$step"
done
