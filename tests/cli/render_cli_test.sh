#!/usr/bin/env bash
# geodex render: the PNG has the requested size, is not blank, and shows the distance gradient
# (the quadrant holding the source is darker: low distances are dark in the colour map, and moving
# the source moves the dark corner); PLY and glTF exports are valid; local and remote renders are
# the same bytes; bad arguments give one-line errors and exit 2.
# Env: GEODEX, GEODEXD (the binaries), DATA (tests/data), PROBE (png_probe.py).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
probe() { /usr/bin/python3 "$PROBE" "$@"; }
value() { /usr/bin/python3 -c "import json,sys; d=json.load(open('$1')); print($2)"; }

# Source in the bottom-left corner of the top view, then in the top-right corner.
"$GEODEX" render sample:terrain --sources 0 --view top --size 320x200 --output "$tmp/a.png"
check "render exits 0" test $? -eq 0
probe "$tmp/a.png" --bar-width 0 >"$tmp/a.json"  # 320 wide: no colour bar
check "size 320x200" test "$(value "$tmp/a.json" "d['width'], d['height']")" = "320 200"
check "not blank (many colours)" test "$(value "$tmp/a.json" "d['colours'] > 1000")" = True
check "the mesh covers part of the picture" test "$(value "$tmp/a.json" "0.2 < d['painted'] < 0.95")" = True
check "source corner darker than the far corner" \
  test "$(value "$tmp/a.json" "d['brightness']['bl'] < d['brightness']['tr'] - 50")" = True
"$GEODEX" render sample:terrain --sources 4224 --view top --size 320x200 --output "$tmp/b.png"
probe "$tmp/b.png" --bar-width 0 >"$tmp/b.json"
check "moving the source moves the dark corner" \
  test "$(value "$tmp/b.json" "d['brightness']['tr'] < d['brightness']['bl'] - 50")" = True

# The legend's labels are round numbers that fit: no text pixel (the font's grey 30) in the
# image's last two columns, at 1200 px and at the narrowest picture with a bar; the labels are
# there (text pixels right of the bar); --levels labels each isoline (more text in the mesh's area).
legend_fits() {  # legend_fits PNG: text right of the bar, none at the edge
  /usr/bin/python3 - "$1" "$PROBE" <<'PY'
import importlib.util, sys
spec = importlib.util.spec_from_file_location("probe", sys.argv[2]); probe = importlib.util.module_from_spec(spec); spec.loader.exec_module(probe)
w, h, rows = probe.read_png(sys.argv[1])
text = lambda x, y: rows[y][3 * x:3 * x + 3] == bytes([30, 30, 30])
right = [(x, y) for y in range(h) for x in range(w - 112 + 8 + 16 + 4, w) if text(x, y)]
edge = [(x, y) for y in range(h) for x in range(w - 2, w) if text(x, y)]
sys.exit(0 if len(right) > 100 and not edge else 1)
PY
}
"$GEODEX" render sample:terrain --sources 0 --view top --size 1200x900 --output "$tmp/wide.png"
check "legend labels fit (1200 px)" legend_fits "$tmp/wide.png"
"$GEODEX" render sample:terrain --sources 0 --view top --size 320x200 --output "$tmp/narrow.png"
check "legend labels fit (320 px)" legend_fits "$tmp/narrow.png"
"$GEODEX" render "$DATA/knight.off" --sources 0 --view top --size 400x300 --output "$tmp/knight.png"
check "legend labels fit (knight)" legend_fits "$tmp/knight.png"
"$GEODEX" render sample:terrain --sources 0 --view top --levels 0.5,1,1.5 --output "$tmp/levels.png"
check "render --levels: exit 0" test $? -eq 0
"$GEODEX" render sample:terrain --sources 0 --view top --isolines 2 --levels 1 --output "$tmp/x.png" 2>"$tmp/err.txt"
check "render --isolines and --levels: refused" test $? -eq 2
check "labelled isolines: text in the mesh's area" /usr/bin/python3 - "$tmp/levels.png" "$tmp/bar0.png" "$PROBE" <<'PY'
import importlib.util, subprocess, sys
spec = importlib.util.spec_from_file_location("probe", sys.argv[3]); probe = importlib.util.module_from_spec(spec); spec.loader.exec_module(probe)
def grey_on_white(path):  # text pixels with white right above or below them (the label's box)
    w, h, rows = probe.read_png(path)
    n = 0
    for y in range(1, h - 1):
        for x in range(w - 112):
            if rows[y][3 * x:3 * x + 3] == bytes([30, 30, 30]) and (rows[y - 1][3 * x:3 * x + 3] == b"\xff\xff\xff" or rows[y + 1][3 * x:3 * x + 3] == b"\xff\xff\xff"):
                n += 1
    return n
sys.exit(0 if grey_on_white(sys.argv[1]) > 30 else 1)
PY

# The colour bar (800 wide): the map from purple (0, bottom) to yellow (the largest distance, top)
# in the rightmost 112 pixels, its bar at x = 800 - 112 + 8 .. +24, y from 15% to 85%.
"$GEODEX" render sample:terrain --sources 0 --view top --output "$tmp/bar.png"
probe "$tmp/bar.png" --bar-width 112 --pixel 700,95 --pixel 700,505 --pixel 700,300 >"$tmp/bar.json"
check "colour bar: yellow at the top" test "$(value "$tmp/bar.json" "(lambda p: p[0] > 200 and p[1] > 200 and p[2] < 100)(d['pixels'][0])")" = True
check "colour bar: purple at the bottom" test "$(value "$tmp/bar.json" "(lambda p: p[0] < 100 and p[2] > 70 and p[1] < 40)(d['pixels'][1])")" = True
check "colour bar: green-blue in the middle" test "$(value "$tmp/bar.json" "(lambda p: p[1] > p[0])(d['pixels'][2])")" = True
check "colour bar: the mesh keeps its corners (source at bottom-left)" \
  test "$(value "$tmp/bar.json" "d['brightness']['bl'] < d['brightness']['tr'] - 50")" = True
"$GEODEX" render sample:terrain --sources 0 --view top --size 319x300 --output "$tmp/nobar.png"
probe "$tmp/nobar.png" --pixel 310,150 >"$tmp/nobar.json"
check "no colour bar below 320 pixels" test "$(value "$tmp/nobar.json" "d['pixels'][0] == [255, 255, 255]")" = True

# The default view shows the sources: on the sphere a source at its lowest vertex is hidden from
# the iso view, and auto picks one that shows it (a black marker in the picture).
lowest=$("$GEODEX" locate sample:sphere --points p:0:0:-100 | cut -f2)
"$GEODEX" render sample:sphere --sources "$lowest" --view iso --output "$tmp/iso.png"
"$GEODEX" render sample:sphere --sources "$lowest" --output "$tmp/auto.png"
probe "$tmp/iso.png" --bar-width 112 >"$tmp/iso.json"
probe "$tmp/auto.png" --bar-width 112 >"$tmp/auto.json"
check "the lowest vertex ($lowest) is a vertex" test -n "$lowest" -a "${lowest#*:}" = "$lowest"
check "iso hides the bottom source" test "$(value "$tmp/iso.json" "d['black']")" = 0
check "auto shows it" test "$(value "$tmp/auto.json" "d['black'] > 10")" = True

# Every layer and view.
"$GEODEX" render "$DATA/kitten.off" --sources 0,1250 --isolines 12 --voronoi --delaunay \
  --path 5 2000 --view front --output "$tmp/all.png"
check "all layers: exit 0" test $? -eq 0
probe "$tmp/all.png" >"$tmp/all.json"
check "all layers: default size 800x600" test "$(value "$tmp/all.json" "d['width'], d['height']")" = "800 600"
for view in iso top bottom front back left right; do
  "$GEODEX" render "$DATA/knight.off" --sources 0 --view "$view" --size 64x48 --output "$tmp/v.png"
  check "view $view" test $? -eq 0
done

# 3D exports.
"$GEODEX" render "$DATA/knight.off" --sources 0 --output "$tmp/k.gltf"
check "gltf: exit 0" test $? -eq 0
check "gltf: valid, 502 vertices" /usr/bin/python3 -c "
import json, base64
d = json.load(open('$tmp/k.gltf'))
assert d['asset']['version'] == '2.0'
assert d['accessors'][0]['count'] == 502 and d['accessors'][2]['count'] == 3000
buf = d['buffers'][0]
assert len(base64.b64decode(buf['uri'].split(',', 1)[1])) == buf['byteLength']"
"$GEODEX" render "$DATA/knight.off" --sources 0 --output "$tmp/k.ply"
check "ply: colours and distances" bash -c "head -c 400 '$tmp/k.ply' | grep -a -q 'property uchar red' && head -c 400 '$tmp/k.ply' | grep -a -q 'property double distance'"

# Remote mode renders the same picture.
start_geodexd "$tmp/server.log" --pool-threads 2 --shutdown_grace_seconds 5
check "server started" test -n "$geodexd_port"
"$GEODEX" --server "127.0.0.1:$geodexd_port" render "$DATA/kitten.off" --sources 0,1250 \
  --isolines 12 --voronoi --delaunay --path 5 2000 --view front --output "$tmp/remote.png"
check "remote render: exit 0" test $? -eq 0
check "remote render: same bytes as local" cmp -s "$tmp/all.png" "$tmp/remote.png"

# A travel-time map (--speed): at 7.2 km/h every time is half the distance, so the colours of the
# mesh are the distance map's exactly (both run from 0 to their largest value); the colour bar's
# strip differs (its caption says travel time, its labels seconds). A friction map changes them.
"$GEODEX" render sample:terrain --sources 0 --view top --output "$tmp/dist.png"
"$GEODEX" render sample:terrain --sources 0 --view top --speed constant:7.2 --output "$tmp/time.png"
check "render --speed exits 0" test $? -eq 0
check "travel-time map: the mesh's colours are the distance map's, the legend is not" \
  /usr/bin/python3 - "$tmp/dist.png" "$tmp/time.png" "$PROBE" <<'PY'
import importlib.util, sys
spec = importlib.util.spec_from_file_location("probe", sys.argv[3]); probe = importlib.util.module_from_spec(spec); spec.loader.exec_module(probe)
w, h, a = probe.read_png(sys.argv[1])
_, _, b = probe.read_png(sys.argv[2])
mesh = lambda rows: [bytes(r[:3 * (w - 112)]) for r in rows]
strip = lambda rows: [bytes(r[3 * (w - 112):]) for r in rows]
sys.exit(0 if mesh(a) == mesh(b) and strip(a) != strip(b) else 1)
PY
"$GEODEX" render sample:terrain --sources 0 --view top --speed constant:7.2 --cost-epsilon 0.5 \
  --face-weights <(/usr/bin/python3 -c 'print("\n".join("1" if f < 4096 else "3" for f in range(8192)))') \
  --output "$tmp/weighted.png"
check "render --face-weights exits 0" test $? -eq 0
check "weights change the travel-time map" test "$(cmp -s "$tmp/time.png" "$tmp/weighted.png"; echo $?)" = 1

# Bad arguments.
for bad in "--size 5x5" "--view sideways" "--isolines 1"; do
  # shellcheck disable=SC2086
  "$GEODEX" render "$DATA/knight.off" --sources 0 --output "$tmp/x.png" $bad 2>"$tmp/err.txt"
  check "bad $bad: exit 2" test $? -eq 2
  check "bad $bad: one line" test "$(wc -l <"$tmp/err.txt")" -eq 1
done
"$GEODEX" render "$DATA/knight.off" --sources 0 --output "$tmp/x.jpg" 2>"$tmp/err.txt"
check "bad extension: exit 2" test $? -eq 2
"$GEODEX" render "$DATA/knight.off" --sources 99999 --output "$tmp/x.png" 2>"$tmp/err.txt"
check "bad source: exit 2" test $? -eq 2

finish "render cli"
