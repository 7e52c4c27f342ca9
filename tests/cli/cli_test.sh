#!/usr/bin/env bash
# Drives the geodex CLI as a user would: outputs, exit codes, one-line errors.
# Env: GEODEX (the binary), DATA (tests/data).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
# remote_mode.sh runs this script again with GEODEX_SERVER set (every command through geodexd) and
# GEODEX_MODE=remote: the same checks, except that local-only flags must be refused there.
local_mode() { [ "${GEODEX_MODE:-local}" = local ]; }
expect_usage() {  # NAME PATTERN ARGS...: exit 2, one line naming PATTERN
  local name="$1" pattern="$2"
  shift 2
  expect_code "$name" 2 "$pattern" "$@"
}

# --version: CMake's project version (VERSION, given by ctest; the remote rerun leaves it out).
if [ -n "${VERSION:-}" ]; then
  check "--version prints CMake's project version" test "$("$GEODEX" --version)" = "geodex $VERSION"
fi

# info: key: value lines with the documented keys; json parses; exit 0.
"$GEODEX" info "$DATA/kitten.off" >"$tmp/info.txt"
check "info exits 0" test $? -eq 0
for key in vertices faces boundary_loops components isolated_vertices non_manifold_edges \
  non_manifold_vertices degenerate_faces saddle_vertices bytes; do
  check "info has $key" grep -q "^$key: [0-9]" "$tmp/info.txt"
done
check "info vertices count" grep -qx "vertices: 2500" "$tmp/info.txt"
check "info faces count" grep -qx "faces: 5000" "$tmp/info.txt"
"$GEODEX" info "$DATA/kitten.off" --format json >"$tmp/info.json"
check "info json parses" /usr/bin/python3 -c "import json,sys; d=json.load(open('$tmp/info.json')); sys.exit(0 if d['vertices']==2500 and d['faces']==5000 else 1)"
"$GEODEX" info sample:terrain >/dev/null
check "info on a sample" test $? -eq 0

# info on an unreadable file: non-zero, one line naming the file.
printf 'OFF\n3 1 0\n0 0 0\n1 0\n' >"$tmp/broken.off"
"$GEODEX" info "$tmp/broken.off" >/dev/null 2>"$tmp/err.txt"
check "broken mesh exits 3" test $? -eq 3
check "broken mesh: one line" test "$(wc -l <"$tmp/err.txt")" -eq 1
check "broken mesh: names the file" grep -q "broken.off" "$tmp/err.txt"
"$GEODEX" info "$tmp/missing.off" >/dev/null 2>"$tmp/err.txt"
check "missing file exits 3" test $? -eq 3

# distances: one line per vertex, %.17g, exact on the flat domain (Euclidean).
"$GEODEX" distances "$DATA/bump-domain.off" --sources 0 --stats >"$tmp/d.txt" 2>"$tmp/stats.json"
check "distances exits 0" test $? -eq 0
check "distances: one line per vertex" test "$(wc -l <"$tmp/d.txt")" -eq 4172
check "stats json has solve_ms" /usr/bin/python3 -c "import json; d=json.load(open('$tmp/stats.json')); assert d['solve_ms'] >= 0 and d['windows_created'] > 0"
check "flat domain is Euclidean" /usr/bin/python3 - "$DATA/bump-domain.off" "$tmp/d.txt" <<'PY'
import math, sys
lines = open(sys.argv[1]).read().split('\n')
nv = int(lines[1].split()[0])
p = [tuple(map(float, lines[2 + i].split())) for i in range(nv)]
d = [float(x) for x in open(sys.argv[2])]
worst = max(abs(d[i] - math.dist(p[i], p[0])) for i in range(nv))
sys.exit(0 if worst <= 1e-10 * max(d) else 1)
PY
"$GEODEX" distances "$DATA/bump-domain.off" --sources 0 --output "$tmp/o.txt"
check "--output writes the same numbers" cmp -s "$tmp/o.txt" "$tmp/d.txt"
if local_mode; then
  "$GEODEX" distances "$DATA/bump-domain.off" --sources 0 --method dijkstra >"$tmp/dj.txt"
  check "dijkstra >= exact" /usr/bin/python3 -c "
a=[float(x) for x in open('$tmp/d.txt')]; b=[float(x) for x in open('$tmp/dj.txt')]
assert all(y >= x*(1-1e-12) for x,y in zip(a,b)) and any(y > x*1.001 for x,y in zip(a,b))"
else
  expect_usage "dijkstra refused remotely" "--method dijkstra: local only" \
    distances "$DATA/bump-domain.off" --sources 0 --method dijkstra
fi

# path: first line the length, then 'x y z' + simplex lines from --from to --to; astar == full.
"$GEODEX" path "$DATA/kitten.off" --from 0 --to f:100:0.2:0.3:0.5 --stats >"$tmp/p.txt" 2>"$tmp/ps.json"
check "path exits 0" test $? -eq 0
if local_mode; then
  "$GEODEX" path "$DATA/kitten.off" --from 0 --to f:100:0.2:0.3:0.5 --method full >"$tmp/pf.txt"
  check "astar and full give the same length" /usr/bin/python3 -c "
a=float(open('$tmp/p.txt').readline()); b=float(open('$tmp/pf.txt').readline())
assert abs(a-b) <= 1e-12*b and a > 0"
else
  expect_usage "path --method full refused remotely" "--method full: local only" \
    path "$DATA/kitten.off" --from 0 --to f:100:0.2:0.3:0.5 --method full
fi
check "path starts at the source vertex" /usr/bin/python3 -c "
l=open('$tmp/p.txt').read().split(chr(10)); assert l[1].split()[3:]==['v','0'], l[1]"
check "path ends at the target face point" /usr/bin/python3 -c "
l=[x for x in open('$tmp/p.txt').read().split(chr(10)) if x]; t=l[-1].split()
assert t[3]=='f' and t[4]=='100', t"
check "path points have lengths summing to the distance" /usr/bin/python3 -c "
import math
l=[x.split() for x in open('$tmp/p.txt').read().split(chr(10)) if x]
pts=[tuple(map(float,x[:3])) for x in l[1:]]
s=sum(math.dist(a,b) for a,b in zip(pts,pts[1:])); d=float(l[0][0])
assert abs(s-d) <= 1e-9*d, (s,d)"
check "path stats json" /usr/bin/python3 -c "import json; d=json.load(open('$tmp/ps.json')); assert d['windows_created']>0"

# matrix: one row per source, tab-separated, equal to the path lengths.
"$GEODEX" matrix "$DATA/kitten.off" --sources 0,1250 --targets 7,f:100:0.2:0.3:0.5 >"$tmp/m.txt"
check "matrix exits 0" test $? -eq 0
check "matrix shape and values" /usr/bin/python3 -c "
rows=[r.split(chr(9)) for r in open('$tmp/m.txt').read().split(chr(10)) if r]
assert len(rows)==2 and all(len(r)==2 for r in rows)
d=float(open('$tmp/p.txt').readline()); assert abs(float(rows[0][1])-d) <= 1e-12*d"

# distances --at: estimate and exact per point; p:X:Y:Z positions are located on the surface.
"$GEODEX" distances "$DATA/bump-domain.off" --sources 0 --at f:10:0.2:0.3:0.5,e:0:1:0.5,p:0.1:0.2:0.5 >"$tmp/at.txt"
check "--at exits 0" test $? -eq 0
check "--at: estimate equals exact on a flat domain" /usr/bin/python3 -c "
for l in open('$tmp/at.txt'):
    f=l.split(chr(9)); e=float(f[1].split()[1]); x=float(f[2].split()[1])
    assert abs(e-x) <= 1e-10*max(1,x), l
assert len(open('$tmp/at.txt').read().split(chr(10)))==4"

# bad arguments: exit 2, one line naming the problem.
expect_usage "unknown vertex" "vertex 99999" distances "$DATA/knight.off" --sources 99999
expect_usage "bad spec" "bad point 'x:1'" distances "$DATA/knight.off" --sources x:1
expect_usage "bad T" "outside \[0, 1\]" distances "$DATA/knight.off" --sources e:0:1:1.5
expect_usage "bad method" "--method" distances "$DATA/knight.off" --sources 0 --method foo
expect_usage "unknown option" "--frobnicate" distances "$DATA/knight.off" --sources 0 --frobnicate 1
expect_usage "unknown command" "frobnicate" frobnicate
expect_usage "missing sources" "usage" distances "$DATA/knight.off"
expect_usage "path to unknown vertex" "vertex 9999" path "$DATA/knight.off" --from 0 --to 9999
# Several --from points: the path from the nearest, named on stderr, its length the smallest.
"$GEODEX" path "$DATA/knight.off" --from 0,1,5 --to 2 >"$tmp/many.txt" 2>"$tmp/many.err"
check "path from the nearest of several: exit 0" test $? -eq 0
best=""
for v in 0 1 5; do
  d=$("$GEODEX" path "$DATA/knight.off" --from $v --to 2 | head -1)
  if [ -z "$best" ] || python3 -c "import sys; sys.exit(0 if float('$d') < float('$best') else 1)"; then best=$d; nearest=$v; fi
done
check "path from the nearest of several: the shortest length" test "$(head -1 "$tmp/many.txt")" = "$best"
check "path from the nearest of several: named" grep -q "the nearest is point [0-9] ($nearest)" "$tmp/many.err"
expect_usage "bad path method" "--method" path "$DATA/knight.off" --from 0 --to 2 --method foo
expect_usage "matrix bad target" "--targets" matrix "$DATA/knight.off" --sources 0 --targets f:0:2:0:0
expect_usage "bad position" "p:1:2" distances "$DATA/knight.off" --sources p:1:2
expect_usage "unwritable output" "cannot write $tmp/none/x.txt: No such file or directory" \
  distances "$DATA/knight.off" --sources 0 --output "$tmp/none/x.txt"
expect_usage "unwritable geometry output" "cannot write $tmp/none/x.json: No such file" \
  isolines "$DATA/knight.off" --sources 0 --count 3 --output "$tmp/none/x.json"

# --help anywhere after the command prints that command's help (with the point grammar), exit 0.
for cmd in matrix distances path; do
  "$GEODEX" "$cmd" --sources 0 --help >"$tmp/help.txt" 2>&1
  check "$cmd --help exits 0" test $? -eq 0
  check "$cmd --help shows its usage" grep -q "^  $cmd MESH" "$tmp/help.txt"
  check "$cmd --help lists p:X:Y:Z" grep -q "p:X:Y:Z" "$tmp/help.txt"
done
"$GEODEX" --help | grep -q "p:X:Y:Z"
check "geodex --help lists p:X:Y:Z" test $? -eq 0

# A directory as MESH says so.
"$GEODEX" info "$tmp" >/dev/null 2>"$tmp/err.txt"
check "directory exits 3" test $? -eq 3
check "directory: says it is a directory" grep -q "is a directory" "$tmp/err.txt"
# Remotely a directory may share its name with a mesh on the server (the sample "terrain" beside a
# "terrain" directory): the server's mesh is meant.
if ! local_mode; then
  geodex_abs=$(realpath "$GEODEX")
  mkdir -p "$tmp/cwd/terrain"
  (cd "$tmp/cwd" && "$geodex_abs" info terrain >"$tmp/named.txt" 2>"$tmp/err.txt")
  check "a directory named like a server mesh: the mesh" grep -qx "vertices: 4225" "$tmp/named.txt"
fi

# --format json: the same numbers as the text formats, parsed by a real JSON parser.
K="$DATA/kitten.off"
"$GEODEX" distances "$K" --sources 0 --max-distance 20 >"$tmp/d.txt"
"$GEODEX" distances "$K" --sources 0 --max-distance 20 --format json >"$tmp/d.json"
check "distances json = text (inf -> null)" /usr/bin/python3 - "$tmp/d.txt" "$tmp/d.json" <<'PY'
import json, math, sys
text = [float(x) for x in open(sys.argv[1])]
js = json.load(open(sys.argv[2]))["distances"]
assert len(js) == len(text) == 2500 and any(math.isinf(t) for t in text)
assert all((j is None) if math.isinf(t) else j == t for t, j in zip(text, js))
PY
"$GEODEX" distances "$K" --sources 0 --at 7,f:30:0.2:0.2:0.6 >"$tmp/at.txt"
"$GEODEX" distances "$K" --sources 0 --at 7,f:30:0.2:0.2:0.6 --format json >"$tmp/at.json"
check "distances --at json = text" /usr/bin/python3 - "$tmp/at.txt" "$tmp/at.json" <<'PY'
import json, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1])]
js = json.load(open(sys.argv[2]))["points"]
assert [r[0] for r in rows] == [p["point"] for p in js]
assert all(float(r[2].split()[1]) == p["exact"] and int(r[3].split()[1]) == p["source"] for r, p in zip(rows, js))
PY
"$GEODEX" path "$K" --from 3 --to f:300:0.1:0.2:0.7 >"$tmp/p.txt"
"$GEODEX" path "$K" --from 3 --to f:300:0.1:0.2:0.7 --format json >"$tmp/p.json"
check "path json = text, with simplices" /usr/bin/python3 - "$tmp/p.txt" "$tmp/p.json" <<'PY'
import json, sys
lines = open(sys.argv[1]).read().split("\n")[:-1]
js = json.load(open(sys.argv[2]))
assert float(lines[0]) == js["length"] and len(lines) - 1 == len(js["points"])
for line, p in zip(lines[1:], js["points"]):
    f = line.split()
    assert [float(x) for x in f[:3]] == p["p"]
    assert f[3] in p and (f[3] != "v" or int(f[4]) == p["v"])
assert js["points"][0]["v"] == 3 and js["points"][-1]["f"][0] == 300
PY
"$GEODEX" matrix "$K" --sources 0,9 --targets 2,44,1000 --max-distance 30 >"$tmp/m.txt"
"$GEODEX" matrix "$K" --sources 0,9 --targets 2,44,1000 --max-distance 30 --format json >"$tmp/m.json"
check "matrix json = text" /usr/bin/python3 - "$tmp/m.txt" "$tmp/m.json" <<'PY'
import json, math, sys
text = [[float(x) for x in l.split("\t")] for l in open(sys.argv[1])]
js = json.load(open(sys.argv[2]))
assert js["rows"] == 2 and js["cols"] == 3
assert all((j is None) if math.isinf(t) else j == t for tr, jr in zip(text, js["values"]) for t, j in zip(tr, jr))
PY
"$GEODEX" info "$K" --format json >"$tmp/i.json"
check "info json bbox is numeric" /usr/bin/python3 -c "import json; d=json.load(open('$tmp/i.json')); assert all(isinstance(x, float) for x in d['bbox_min'] + d['bbox_max']) and d['bbox_min'][1] < d['bbox_max'][1]"
expect_usage "bad format" "--format" matrix "$K" --sources 0 --targets 1 --format xml

# --directions: on the flat domain every vertex's direction points straight at the source.
"$GEODEX" distances "$DATA/bump-domain.off" --sources 0 --directions >"$tmp/dir.txt"
check "directions: flat domain, straight at the source" /usr/bin/python3 - "$DATA/bump-domain.off" "$tmp/dir.txt" <<'PY'
import math, sys
lines = open(sys.argv[1]).read().split("\n")
nv = int(lines[1].split()[0])
p = [tuple(map(float, lines[2 + i].split())) for i in range(nv)]
rows = [l.split("\t") for l in open(sys.argv[2]).read().splitlines()]
assert len(rows) == nv and [float(c) for c in rows[0][1].split()] == [0, 0, 0]
for i in range(1, nv):
    d = [float(c) for c in rows[i][1].split()]
    want = [(p[0][k] - p[i][k]) / math.dist(p[0], p[i]) for k in range(3)]
    assert max(abs(a - b) for a, b in zip(d, want)) < 1e-9, (i, d, want)
PY
"$GEODEX" distances "$K" --sources 0 --directions --max-distance 20 --format json >"$tmp/dir.json"
check "directions json: null beyond max-distance, unit vectors elsewhere" /usr/bin/python3 -c "
import json, math
d = json.load(open('$tmp/dir.json'))
assert len(d['directions']) == 2500
assert all((v is None) == (x is None) for v, x in zip(d['directions'], d['distances']))
assert all(abs(math.hypot(*v) - 1) < 1e-12 for v in d['directions'][1:] if v is not None)"
# --directions with --at: each point's own direction; on the flat domain straight at the source,
# from face points and vertices alike (0 0 0 at the source itself).
"$GEODEX" distances "$DATA/bump-domain.off" --sources 0 --directions \
  --at f:10:0.2:0.3:0.5,f:57:0.6:0.2:0.2,f:200:0.1:0.1:0.8,9,0 >"$tmp/dirat.txt"
check "directions at points: flat domain, straight at the source" /usr/bin/python3 - "$DATA/bump-domain.off" "$tmp/dirat.txt" <<'PY'
import math, sys
lines = open(sys.argv[1]).read().split("\n")
nv, nf = map(int, lines[1].split()[:2])
p = [tuple(map(float, lines[2 + i].split())) for i in range(nv)]
faces = [list(map(int, lines[2 + nv + f].split()[1:4])) for f in range(nf)]
def position(spec):
    if spec.startswith("f:"):
        _, f, *b = spec.split(":")
        return tuple(sum(float(b[k]) * p[faces[int(f)][k]][c] for k in range(3)) for c in range(3))
    return p[int(spec)]
rows = [l.split("\t") for l in open(sys.argv[2]).read().splitlines()]
assert len(rows) == 5 and all(r[4].startswith("direction ") for r in rows), rows
for r in rows[:4]:
    q = position(r[0])
    d = [float(c) for c in r[4].split()[1:]]
    want = [(p[0][k] - q[k]) / math.dist(p[0], q) for k in range(3)]
    assert max(abs(a - b) for a, b in zip(d, want)) < 1e-9, (r, want)
assert rows[4][4] == "direction 0 0 0", rows[4]
PY
"$GEODEX" distances "$K" --sources 0 --at f:4989:0.2:0.3:0.5,5,2400 --directions --max-distance 20 \
  --format json >"$tmp/dirat.json"
check "directions at points json: null beyond max-distance, unit vectors elsewhere" /usr/bin/python3 -c "
import json, math
d = json.load(open('$tmp/dirat.json'))['points']
assert [p['exact'] is None for p in d] == [False, False, True], d
assert d[2]['direction'] is None and all(abs(math.hypot(*p['direction']) - 1) < 1e-12 for p in d[:2])"
expect_usage "directions not in GeoJSON" "--directions" distances "$K" --sources 0 --at 5 --directions \
  --output "$tmp/x.geojson"

# Snapping is never silent: locate reports it, --stats carries it, a far point is warned about,
# --max-snap refuses it naming the point.
"$GEODEX" locate "$K" --points p:0:0:0,p:0:100:0 >"$tmp/loc.txt"
check "locate exits 0" test $? -eq 0
check "locate: one line per point, snap distance last" /usr/bin/python3 - "$tmp/loc.txt" "$K" <<'PY'
import math, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1])]
assert [r[0] for r in rows] == ["p:0:0:0", "p:0:100:0"]
for (q, spec, xyz, snap) in rows:
    query = [float(x) for x in q[2:].split(":")]
    at = [float(x) for x in xyz.split()]
    assert abs(math.dist(query, at) - float(snap.split()[1])) <= 1e-12 * (1 + math.dist(query, at))
assert rows[0][1] == "2461"  # the nearest vertex of the origin on the kitten
PY
"$GEODEX" locate "$K" --points p:0:0:0 --format json >"$tmp/loc.json"
check "locate json" /usr/bin/python3 -c "import json; d=json.load(open('$tmp/loc.json'))['points'][0]; assert d['point']=='2461' and d['snap_distance'] > 2"
expect_usage "locate --max-snap refuses a far point" "p:0:100:0 is 19.4561 from the surface" \
  locate "$K" --points p:0:0:0,p:0:100:0 --max-snap 5
expect_usage "locate takes positions" "not a position" locate "$K" --points 7
expect_usage "path --max-snap" "--to: p:0:100:0 is" path "$K" --from 1 --to p:0:100:0 --max-snap 1
"$GEODEX" path "$K" --from 1 --to p:0:100:0 --stats >/dev/null 2>"$tmp/snap.err"
check "a far snap is warned about" grep -q "^geodex: warning: --to: p:0:100:0 is 19.4561 from the surface" "$tmp/snap.err"
check "--stats carries snap_max" /usr/bin/python3 -c "import json; d=json.loads(open('$tmp/snap.err').read().splitlines()[-1]); assert abs(d['snap_max'] - 19.456143372030692) < 1e-9 and d['snap_point'] == 'p:0:100:0'"
"$GEODEX" path "$K" --from 1 --to p:-1.203724:-1.917213:1.356663 2>"$tmp/near.err" >/dev/null
check "a snap on the surface is not warned about" test ! -s "$tmp/near.err"

finish "cli"
