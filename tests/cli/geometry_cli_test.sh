#!/usr/bin/env bash
# Drives geodex isolines / voronoi / delaunay as a user would: JSON, OBJ and SVG outputs, exit
# codes, one-line errors. Env: GEODEX (the binary), DATA (tests/data).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
py=/usr/bin/python3

# isolines on a closed mesh: JSON on stdout, approximate, every polyline closed, K-1 levels.
"$GEODEX" isolines "$DATA/kitten.off" --sources 0,1234 --count 5 >"$tmp/iso.json"
check "isolines exits 0" test $? -eq 0
check "isolines json: approximate, 4 levels, closed loops on points of their edges" $py - "$tmp/iso.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["approximate"] is True and d["kind"] == "isolines"
assert len(d["levels"]) == 4 and d["levels"] == sorted(d["levels"])
assert len(d["polylines"]) >= 4
for p in d["polylines"]:
    assert p["closed"] is True and p["level"] in d["levels"]
    for q in p["points"]:
        assert len(q["p"]) == 3 and len(q["e"]) == 3 and 0 <= q["e"][2] <= 1
PY
# Explicit levels on the flat domain: circles around the source (vertex 0), within a fraction of
# the mean edge length (0.038).
"$GEODEX" isolines "$DATA/bump-domain.off" --sources 0 --levels 0.3,0.6 >"$tmp/iso2.json"
check "isolines --levels exits 0" test $? -eq 0
check "isolines on the flat domain are circles" $py - "$tmp/iso2.json" "$DATA/bump-domain.off" <<'PY'
import json, math, sys
d = json.load(open(sys.argv[1]))
lines = open(sys.argv[2]).read().split("\n")
s = tuple(map(float, lines[2].split()))
assert d["levels"] == [0.3, 0.6] and len(d["polylines"]) >= 2
worst = max(abs(math.dist(q["p"], s) - p["level"]) for p in d["polylines"] for q in p["points"])
assert worst < 0.01, worst
PY
"$GEODEX" isolines "$DATA/kitten.off" --sources 0 --count 4 --output "$tmp/iso.obj"
check "isolines .obj exits 0" test $? -eq 0
check "isolines .obj has v and l lines" $py - "$tmp/iso.obj" <<'PY'
import sys
rows = [r.split() for r in open(sys.argv[1]) if r.strip() and not r.startswith("#")]
v = sum(1 for r in rows if r[0] == "v")
ls = [r for r in rows if r[0] == "l"]
assert v > 10 and len(ls) >= 3
assert all(1 <= int(i) <= v for r in ls for i in r[1:])
assert all(r[1] == r[-1] for r in ls)  # closed loops repeat their first vertex
PY
"$GEODEX" isolines sample:terrain --sources 100 --count 6 --output "$tmp/iso.svg"
check "isolines .svg exits 0" test $? -eq 0
check "isolines .svg is an SVG with coloured polylines" $py - "$tmp/iso.svg" <<'PY'
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
ns = "{http://www.w3.org/2000/svg}"
assert root.tag == ns + "svg" and float(root.get("width")) > 100
lines = root.findall(ns + "polyline") + root.findall(ns + "polygon")
assert len(lines) >= 5 and len({l.get("stroke") for l in lines}) >= 5
assert root.find(ns + "path") is not None and root.find(ns + "circle") is not None
PY

# voronoi on the flat domain: cells cover the area, boundaries between adjacent sites.
"$GEODEX" voronoi "$DATA/bump-domain.off" --sites 0,100,2000,3000 >"$tmp/vor.json"
check "voronoi exits 0" test $? -eq 0
check "voronoi json: cells, areas, adjacency, boundaries" $py - "$tmp/vor.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["approximate"] is True and d["kind"] == "voronoi"
assert len(d["sites"]) == 4 and len(d["cells"]) == 4
area = sum(c["area"] for c in d["cells"])
assert abs(area - d["total_area"]) < 1e-9 * area and d["total_area"] > 4.5
pairs = {tuple(b["sites"]) for b in d["boundaries"]}
assert pairs == {tuple(p) for p in d["adjacency"]} and len(pairs) >= 3
for c in d["cells"]:
    assert c["whole_faces"] and all(len(f["polygon"]) >= 3 for f in c["fragments"])
PY
"$GEODEX" voronoi "$DATA/bump-domain.off" --sites 0,100,2000,3000 --output "$tmp/vor.svg"
check "voronoi .svg parses" $py -c "import xml.etree.ElementTree as ET; ET.parse('$tmp/vor.svg')"

# delaunay: edges as polylines from site to site, triangles, XL edges (none on this fine mesh).
"$GEODEX" delaunay "$DATA/bump-domain.off" --sites 0,100,2000,3000 >"$tmp/del.json"
check "delaunay exits 0" test $? -eq 0
check "delaunay json: edges join adjacent cells, triangles, no XL edges" $py - "$tmp/del.json" "$tmp/vor.json" <<'PY'
import json, math, sys
d = json.load(open(sys.argv[1]))
v = json.load(open(sys.argv[2]))
assert d["approximate"] is True and d["kind"] == "delaunay"
assert d["xl_edges"] == [] and d["removed_edges"] == []
assert sorted(e["sites"] for e in d["edges"]) == sorted(v["adjacency"])
sites = {s["site"]: s["p"] for s in d["sites"]}
for e in d["edges"]:
    pts = [q["p"] for q in e["points"]]
    assert math.dist(pts[0], sites[e["sites"][0]]) < 1e-9
    assert math.dist(pts[-1], sites[e["sites"][1]]) < 1e-9
    length = sum(math.dist(a, b) for a, b in zip(pts, pts[1:]))
    assert abs(length - e["length"]) < 1e-9 * e["length"]
    assert e["points"][e["edge_start"]]["v"] == e["mesh_edge"][0]
assert len(d["triangles"]) >= 1 and all(len(t) == 3 for t in d["triangles"])
PY
"$GEODEX" delaunay "$DATA/kitten.off" --sites 0,600,1200,1800 --output "$tmp/del.obj"
check "delaunay .obj exits 0" test $? -eq 0
check "delaunay .obj has one l line per edge" test "$(grep -c '^l ' "$tmp/del.obj")" -ge 6

# The solver flags reach the field the geometry is drawn on (asked whole: IsolineQuery, ...):
# lambda = 0.5 moves the isolines, and the answer is the same bytes as a local run's (in
# remote mode this compares the server's answer with the local engine's).
"$GEODEX" isolines "$DATA/kitten.off" --sources 0 --count 5 --lambda 0.5 >"$tmp/iso_lambda.json"
check "isolines --lambda exits 0" test $? -eq 0
"$GEODEX" isolines "$DATA/kitten.off" --sources 0 --count 5 >"$tmp/iso_exact.json"
check "isolines --lambda 0.5 differs from the exact isolines" \
  bash -c '! cmp -s "$1" "$2"' _ "$tmp/iso_lambda.json" "$tmp/iso_exact.json"
env -u GEODEX_SERVER "$GEODEX" isolines "$DATA/kitten.off" --sources 0 --count 5 --lambda 0.5 \
  >"$tmp/iso_lambda_local.json"
check "isolines --lambda: the same bytes as the local engine's" \
  cmp "$tmp/iso_lambda.json" "$tmp/iso_lambda_local.json"
"$GEODEX" voronoi "$DATA/kitten.off" --sites 0,1234 --lambda 1 >"$tmp/vor_lambda.json"
env -u GEODEX_SERVER "$GEODEX" voronoi "$DATA/kitten.off" --sites 0,1234 --lambda 1 \
  >"$tmp/vor_lambda_local.json"
check "voronoi --lambda 1: the same bytes as the local engine's" \
  cmp "$tmp/vor_lambda.json" "$tmp/vor_lambda_local.json"
expect_code "isolines bad lambda" 2 "--lambda" isolines "$DATA/kitten.off" --sources 0 --count 3 --lambda 2
expect_code "delaunay bad max-distance" 2 "--max-distance" delaunay "$DATA/kitten.off" --sites 0,1 --max-distance -1
expect_code "isolines non-finite level" 2 "--levels: must be finite" isolines "$DATA/kitten.off" --sources 0 --levels 1,nan

# bad arguments: exit 2 with one line naming the problem; unreadable mesh: exit 3 (expect_code:
# tests/util/test_preamble.sh).
expect_code "levels and count" 2 "usage" isolines "$DATA/kitten.off" --sources 0 --levels 1 --count 3
expect_code "neither levels nor count" 2 "usage" isolines "$DATA/kitten.off" --sources 0
expect_code "bad count" 2 "--count" isolines "$DATA/kitten.off" --sources 0 --count 1
expect_code "bad level" 2 "--levels" isolines "$DATA/kitten.off" --sources 0 --levels 1,x
expect_code "bad output extension" 2 ".json, .obj, .svg or, on a DEM, a vector file's .geojson, .gpkg, .shp, .fgb" voronoi "$DATA/kitten.off" --sites 0 --output "$tmp/x.txt"
expect_code "missing sites" 2 "usage" voronoi "$DATA/kitten.off"
expect_code "unknown site vertex" 2 "vertex 99999" delaunay "$DATA/kitten.off" --sites 0,99999
expect_code "bad site spec" 2 "--sites" delaunay "$DATA/kitten.off" --sites x:1
expect_code "unknown option" 2 "--frobnicate" voronoi "$DATA/kitten.off" --sites 0 --frobnicate 1
expect_code "missing mesh" 3 "missing.off" voronoi "$tmp/missing.off" --sites 0

finish "geometry cli"
