#!/usr/bin/env bash
# geodex in remote mode against a real geodexd (127.0.0.1, a port it picks): every command that
# remote mode offers prints exactly what local mode prints (timing lines aside), on several meshes;
# mesh management, health, one-line errors and exit codes. Bounded: every wait gives up.
# Env: GEODEX, GEODEXD (the binaries), DATA (tests/data).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
start_geodexd "$tmp/server.log" --data-dir "$tmp/data" --pool-threads 2 --shutdown_grace_seconds 5
port=$geodexd_port
check "server started" test -n "$port"
R=("$GEODEX" --server "127.0.0.1:$port")

"${R[@]}" health >"$tmp/health.txt"
check "health exit 0" test $? -eq 0
check "health prints SERVING" grep -qx SERVING "$tmp/health.txt"

# Local and remote print the same bytes (lines ending in _ms are timings).
same() {  # same NAME ARGS...
  local name="$1"
  shift
  "$GEODEX" "$@" >"$tmp/local.txt" 2>"$tmp/local.err"
  local lrc=$?
  GEODEX_SERVER="127.0.0.1:$port" "$GEODEX" "$@" >"$tmp/remote.txt" 2>"$tmp/remote.err"
  local rrc=$?
  check "$name: exit codes ($lrc local, $rrc remote)" test "$lrc" -eq "$rrc"
  check "$name: output non-empty" test -s "$tmp/local.txt"
  check "$name: identical output" diff <(grep -v '_ms' "$tmp/local.txt") <(grep -v '_ms' "$tmp/remote.txt")
}
for mesh in "$DATA/knight.off" "$DATA/kitten.off" "$DATA/three-peaks.off" sample:terrain; do
  m=$(basename "$mesh")
  same "info $m" info "$mesh"
  same "info json $m" info "$mesh" --format json
  same "distances $m" distances "$mesh" --sources 0,17
  same "distances face source $m" distances "$mesh" --sources f:10:0.2:0.3:0.5
  same "distances max-distance $m" distances "$mesh" --sources 5 --max-distance 0.5
  same "path $m" path "$mesh" --from 3 --to 400
  same "path face points $m" path "$mesh" --from f:1:0.3:0.3:0.4 --to f:300:0.1:0.2:0.7
  same "matrix $m" matrix "$mesh" --sources 0,9,f:5:0.5:0.5:0 --targets 2,44,f:20:0.5:0.25:0.25
  same "at $m" distances "$mesh" --sources 1 --at 7,f:30:0.2:0.2:0.6
  same "isolines $m" isolines "$mesh" --sources 0,f:40:0.2:0.3:0.5 --count 6
  same "isolines levels $m" isolines "$mesh" --sources 3 --levels 0.1,0.5,2
  same "voronoi $m" voronoi "$mesh" --sites 0,100,200,300,f:60:0.3:0.3:0.4
  same "delaunay $m" delaunay "$mesh" --sites 0,100,200,300,400
done
for ext in obj svg; do
  "$GEODEX" voronoi sample:terrain --sites 0,2000,4000,4224 --output "$tmp/local.$ext"
  "${R[@]}" voronoi sample:terrain --sites 0,2000,4000,4224 --output "$tmp/remote.$ext"
  check "voronoi --output .$ext identical" cmp -s "$tmp/local.$ext" "$tmp/remote.$ext"
  check "voronoi --output .$ext non-empty" test -s "$tmp/remote.$ext"
done
same "lambda" distances "$DATA/kitten.off" --sources 0 --lambda 0.1 --lambda-scale mean
# One command, two backends: the options that used to differ between the modes.
same "path lambda" path "$DATA/kitten.off" --from 3 --to 400 --lambda 0.2 --max-distance 500
same "matrix lambda" matrix "$DATA/kitten.off" --sources 0,9 --targets 2,44 --lambda 0.1 --lambda-scale mean
same "matrix k-nearest" matrix "$DATA/kitten.off" --sources 0,9,30 --targets 2,44,100,7 --k-nearest 2
same "matrix max-distance" matrix "$DATA/kitten.off" --sources 0,9 --targets 2,44,1000 --max-distance 0.3
"$GEODEX" render "$DATA/knight.off" --sources 0 --isolines 4 --path 3 400 --output "$tmp/local.ply"
"${R[@]}" render "$DATA/knight.off" --sources 0 --isolines 4 --path 3 400 --output "$tmp/remote.ply"
check "render: identical .ply" cmp -s "$tmp/local.ply" "$tmp/remote.ply"
same_error() {  # same_error NAME ARGS...: the same exit code and a one-line message in both modes
  local name="$1"
  shift
  "$GEODEX" "$@" >/dev/null 2>"$tmp/local.err"
  local lrc=$?
  "${R[@]}" "$@" >/dev/null 2>"$tmp/remote.err"
  local rrc=$?
  check "$name: exit codes ($lrc local, $rrc remote)" test "$lrc" -eq "$rrc" -a "$lrc" -ne 0
  check "$name: one line each" test "$(cat "$tmp/local.err" "$tmp/remote.err" | wc -l)" -eq 2
}
same "directions" distances "$DATA/kitten.off" --sources 0,f:100:0.2:0.3:0.5 --directions
same "directions json" distances "$DATA/knight.off" --sources 3 --directions --format json --max-distance 0.3
same "directions at points" distances "$DATA/kitten.off" --sources 0,f:100:0.2:0.3:0.5 --directions \
  --at f:7:0.1:0.2:0.7,40,e:0:1:0.25
same "directions at points json" distances "$DATA/knight.off" --sources 3 --directions --format json \
  --at f:7:0.1:0.2:0.7,40 --max-distance 0.3
same "locate" locate "$DATA/kitten.off" --points p:0:0:0,p:0:100:0,p:3:40:2
same "locate json" locate "$DATA/kitten.off" --points p:0:0:0 --format json
same "distances json" distances "$DATA/kitten.off" --sources 0,p:1:50:2 --format json --max-distance 20
same "at json" distances "$DATA/kitten.off" --sources 1 --at 7,f:30:0.2:0.2:0.6 --format json
same "path json" path "$DATA/kitten.off" --from p:0:100:0 --to f:300:0.1:0.2:0.7 --format json
same "matrix json" matrix "$DATA/kitten.off" --sources 0,9 --targets 2,44 --format json
same "info json" info "$DATA/kitten.off" --format json
same_error "max-snap" path "$DATA/kitten.off" --from 1 --to p:0:100:0 --max-snap 1
check "max-snap: the same message" diff "$tmp/local.err" "$tmp/remote.err"
same_error "bad option" matrix "$DATA/kitten.off" --sources 0 --targets 1 --bogus 1
same_error "unreachable target" path "$DATA/kitten.off" --from 3 --to 400 --max-distance 1
same_error "bad lambda" path "$DATA/kitten.off" --from 3 --to 400 --lambda 2
same "two --from points: the path from the nearest" path "$DATA/kitten.off" --from 3,4,120 --to 400
for flag in "--max-windows 10" "--no-filter" "--method dijkstra"; do
  "${R[@]}" distances "$DATA/kitten.off" --sources 0 $flag 2>"$tmp/err.txt" >/dev/null
  check "remote $flag: exit 2" test $? -eq 2
  check "remote $flag: names the flag" grep -q -- "^geodex: ${flag%% *}" "$tmp/err.txt"
  check "remote $flag: says why" grep -q "geodexd\|local only" "$tmp/err.txt"
done
same "position source" path "$DATA/kitten.off" --from p:0:0:0 --to 100
"$GEODEX" distances "$DATA/knight.off" --sources 0 --output "$tmp/local-out.txt"
"${R[@]}" distances "$DATA/knight.off" --sources 0 --output "$tmp/remote-out.txt"
check "--output: 502 lines" test "$(wc -l <"$tmp/remote-out.txt")" -eq 502
check "--output: identical files" cmp -s "$tmp/local-out.txt" "$tmp/remote-out.txt"

# The file was uploaded once: the server lists each mesh once.
"${R[@]}" mesh list >"$tmp/list.txt"
check "mesh list exit 0" test $? -eq 0
check "mesh list has the 3 files and 3 samples" test "$(wc -l <"$tmp/list.txt")" -eq 6
check "mesh list names terrain" grep -q $'\tterrain\t' "$tmp/list.txt"
"${R[@]}" mesh upload "$DATA/fertility.off" --name fert >"$tmp/up.txt"
check "mesh upload exit 0" test $? -eq 0
check "mesh upload shows the alias" grep -q $'\tfert\t4494 vertices' "$tmp/up.txt"
"${R[@]}" mesh get fert --format json >"$tmp/get.json"
check "mesh get json" /usr/bin/python3 -c "import json; d=json.load(open('$tmp/get.json')); assert d['display_name']=='fert' and d['vertices']==4494"
check "query by alias" bash -c "'$GEODEX' --server 127.0.0.1:$port distances fert --sources 0 | wc -l | grep -qx 4494"
"${R[@]}" mesh delete fert >/dev/null
check "mesh delete exit 0" test $? -eq 0
"${R[@]}" mesh get fert 2>"$tmp/err.txt"
check "deleted mesh: exit 3" test $? -eq 3
check "deleted mesh: one-line error" test "$(wc -l <"$tmp/err.txt")" -eq 1

# Errors: one line, non-zero exit.
"${R[@]}" distances "$DATA/knight.off" --sources 9999 2>"$tmp/err.txt"
check "bad vertex: exit 2" test $? -eq 2
check "bad vertex: names the flag as local mode does" grep -q -- "--sources: point 9999: vertex 9999 does not exist" "$tmp/err.txt"
check "bad vertex: one line" test "$(wc -l <"$tmp/err.txt")" -eq 1
"${R[@]}" distances no-such-mesh --sources 0 2>"$tmp/err.txt"
check "unknown mesh: exit 3" test $? -eq 3
"$GEODEX" --server 127.0.0.1:1 health 2>"$tmp/err.txt"
check "no server: non-zero exit" test $? -ne 0
check "no server: one line" test "$(wc -l <"$tmp/err.txt")" -eq 1
"$GEODEX" health 2>"$tmp/err.txt"
check "health without --server: exit 2" test $? -eq 2
# A mesh named on the server needs no file here: its geometry comes from GetMeshGeometry (file
# coordinates as geodexd holds them: the same numbers as local mode within round-off).
for cmd in "isolines terrain --sources 0,f:40:0.2:0.3:0.5 --count 5" "voronoi terrain --sites 0,100,4000" \
  "delaunay terrain --sites 0,100,4000,2000,3000"; do
  local_cmd=${cmd/terrain/sample:terrain}
  # shellcheck disable=SC2086
  "${R[@]}" $cmd >"$tmp/byname.json" 2>"$tmp/err.txt"
  check "by name, no file: ${cmd%% *} exits 0" test $? -eq 0
  # shellcheck disable=SC2086
  "$GEODEX" $local_cmd >"$tmp/local.json"
  check "by name: ${cmd%% *} equals local within round-off" /usr/bin/python3 - "$tmp/local.json" "$tmp/byname.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
def worst(x, y):
    if isinstance(x, dict):
        assert x.keys() == y.keys()
        return max([worst(x[k], y[k]) for k in x] or [0])
    if isinstance(x, list):
        assert len(x) == len(y)
        return max([worst(p, q) for p, q in zip(x, y)] or [0])
    if isinstance(x, float):
        return abs(x - y)
    assert x == y, (x, y)
    return 0
assert worst(a, b) <= 1e-12, worst(a, b)
PY
done
"${R[@]}" render terrain --sources 0 --isolines 4 --output "$tmp/byname.png"
check "by name, no file: render exits 0" test $? -eq 0
check "by name: render wrote a PNG" test -s "$tmp/byname.png"

finish "remote cli"
