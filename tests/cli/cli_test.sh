#!/usr/bin/env bash
# Drives the geodex CLI as a user would: outputs, exit codes, one-line errors.
# Env: GEODEX (the binary), DATA (tests/data).
set -u
pass=0
fail=0
check() {  # check NAME CONDITION...
  local name="$1"
  shift
  if "$@"; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    echo "FAIL: $name"
  fi
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

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
"$GEODEX" distances "$DATA/bump-domain.off" --sources 0 --method dijkstra >"$tmp/dj.txt"
check "dijkstra >= exact" /usr/bin/python3 -c "
a=[float(x) for x in open('$tmp/d.txt')]; b=[float(x) for x in open('$tmp/dj.txt')]
assert all(y >= x*(1-1e-12) for x,y in zip(a,b)) and any(y > x*1.001 for x,y in zip(a,b))"

# path: first line the length, then 'x y z' + simplex lines from --from to --to; astar == full.
"$GEODEX" path "$DATA/kitten.off" --from 0 --to f:100:0.2:0.3:0.5 --stats >"$tmp/p.txt" 2>"$tmp/ps.json"
check "path exits 0" test $? -eq 0
"$GEODEX" path "$DATA/kitten.off" --from 0 --to f:100:0.2:0.3:0.5 --method full >"$tmp/pf.txt"
check "astar and full give the same length" /usr/bin/python3 -c "
a=float(open('$tmp/p.txt').readline()); b=float(open('$tmp/pf.txt').readline())
assert abs(a-b) <= 1e-12*b and a > 0"
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
expect_usage() {  # NAME PATTERN ARGS...
  local name="$1" pattern="$2"
  shift 2
  "$GEODEX" "$@" >/dev/null 2>"$tmp/err.txt"
  local rc=$?
  check "$name: exit 2" test $rc -eq 2
  check "$name: one line" test "$(wc -l <"$tmp/err.txt")" -eq 1
  check "$name: names '$pattern'" grep -q -- "$pattern" "$tmp/err.txt"
}
expect_usage "unknown vertex" "vertex 99999" distances "$DATA/knight.off" --sources 99999
expect_usage "bad spec" "bad point 'x:1'" distances "$DATA/knight.off" --sources x:1
expect_usage "bad T" "outside \[0, 1\]" distances "$DATA/knight.off" --sources e:0:1:1.5
expect_usage "bad method" "--method" distances "$DATA/knight.off" --sources 0 --method foo
expect_usage "unknown option" "--frobnicate" distances "$DATA/knight.off" --sources 0 --frobnicate 1
expect_usage "unknown command" "frobnicate" frobnicate
expect_usage "missing sources" "usage" distances "$DATA/knight.off"
expect_usage "path to unknown vertex" "vertex 9999" path "$DATA/knight.off" --from 0 --to 9999
expect_usage "path with two points" "one point" path "$DATA/knight.off" --from 0,1 --to 2
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

echo "cli: $pass passed, $fail failed"
test "$fail" -eq 0
