#!/usr/bin/env bash
# Mesh-affine routing end to end on 127.0.0.1: three geodexd replicas behind the nginx gateway
# (deploy/local-cluster.sh). 12 meshes are uploaded through the gateway; every query for a mesh
# reaches the same replica (x-geodex-replica, shown by `geodex --stats`), which is the only one
# holding it; answers equal local mode's. Then one replica is killed (SIGKILL): queries for its
# meshes still succeed through the client's re-upload, on another replica, with the same answers,
# and the other meshes stay where they were. Bounded; stops exactly what it started.
# Env: GEODEX, GEODEXD, NGINX (binaries), CLUSTER (deploy/local-cluster.sh).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
stop_cluster() { GEODEXD="$GEODEXD" NGINX="$NGINX" bash "$CLUSTER" stop "$tmp/cluster"; }
on_exit stop_cluster  # before $tmp is removed
GEODEXD="$GEODEXD" NGINX="$NGINX" bash "$CLUSTER" start "$tmp/cluster" 3 >/dev/null
check "cluster started" test -s "$tmp/cluster/gateway-address"
gw=$(cat "$tmp/cluster/gateway-address")

# 12 small terrains of different sizes (distinct content hashes).
/usr/bin/python3 - "$tmp" <<'PY'
import math, sys
for k in range(12):
    n = 6 + k
    lines = ["OFF", f"{(n + 1) ** 2} {2 * n * n} 0"]
    for j in range(n + 1):
        for i in range(n + 1):
            lines.append(f"{i} {j} {0.4 * math.sin(0.9 * i + k) * math.cos(0.7 * j):.6f}")
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            lines += [f"3 {a} {a + 1} {a + n + 2}", f"3 {a} {a + n + 2} {a + n + 1}"]
    open(f"{sys.argv[1]}/mesh{k}.off", "w").write("\n".join(lines) + "\n")
PY

replica_of() {  # replica_of FILE -> the replica that answered a query for it through the gateway
  "$GEODEX" --server "$gw" distances "$1" --sources 0 --stats 2>&1 >"$tmp/out.txt" |
    sed -n 's/.*"replica": "\([^"]*\)".*/\1/p'
}

declare -A owner
for k in $(seq 0 11); do
  f="$tmp/mesh$k.off"
  "$GEODEX" --server "$gw" mesh upload "$f" >/dev/null
  check "upload mesh$k through the gateway" test $? -eq 0
  first=$(replica_of "$f")
  owner[$k]="$first"
  check "mesh$k answered by a named replica" test -n "$first"
  for _ in 1 2 3; do
    check "mesh$k: same replica every time" test "$(replica_of "$f")" = "$first"
  done
  "$GEODEX" distances "$f" --sources 0 >"$tmp/local.txt"
  check "mesh$k: same answer as local mode" cmp -s "$tmp/out.txt" "$tmp/local.txt"
  # Only the owner holds the mesh: the upload went there and nowhere else.
  # (asked by id: `mesh get FILE` would upload a missing mesh)
  id=$("$GEODEX" --server "$gw" mesh get "$f" 2>/dev/null | cut -f1)
  check "mesh$k: id known" test -n "$id"
  while read -r name address; do
    "$GEODEX" --server "$address" mesh get "$id" >/dev/null 2>&1 </dev/null && has="yes" || has="no"
    if [ "$name" = "$first" ]; then
      check "mesh$k is on its owner $name" test "$has" = "yes"
    else
      check "mesh$k is not on $name" test "$has" = "no"
    fi
  done <"$tmp/cluster/replicas"
done
# HTTP/JSON through the gateway's HTTP port: a mesh asked by its id reaches the replica gRPC uses
# (X-Geodex-Replica), and the answer is the one local mode gives.
gw_http=$(cat "$tmp/cluster/gateway-http-address")
for k in 0 3 7; do
  f="$tmp/mesh$k.off"
  id=$("$GEODEX" --server "$gw" mesh get "$f" 2>/dev/null | cut -f1)
  id=${id#meshes/}
  curl -s -D "$tmp/http_headers.txt" -o "$tmp/http_path.json" -X POST \
    -H 'Content-Type: application/json' "http://$gw_http/v1/meshes/$id:findShortestPath" \
    -d '{"from": {"vertex": 0}, "to": {"vertex": 20}}'
  http_replica=$(sed -n 's/^X-Geodex-Replica: \([^\r]*\).*/\1/p' "$tmp/http_headers.txt" | tr -d '\r')
  check "mesh$k over HTTP: answered by its gRPC owner ${owner[$k]} (got $http_replica)" \
    test "$http_replica" = "${owner[$k]}"
  local_length=$("$GEODEX" path "$f" --from 0 --to 20 --format json |
    /usr/bin/python3 -c 'import json,sys; print(repr(json.load(sys.stdin)["length_m"]))')
  http_length=$(/usr/bin/python3 -c 'import json,sys; print(repr(json.load(open(sys.argv[1]))["distance"]))' "$tmp/http_path.json")
  check "mesh$k over HTTP: the local length ($local_length = $http_length)" test "$local_length" = "$http_length"
done
# An HTTP upload naming its id lands on the replica its queries go to.
f="$tmp/mesh11.off"
id=$("$GEODEX" --server "$gw" mesh get "$f" 2>/dev/null | cut -f1)
id=${id#meshes/}
curl -s -D "$tmp/http_headers.txt" -o /dev/null -X POST -H 'Content-Type: application/octet-stream' \
  --data-binary @"$f" "http://$gw_http/v1/meshes?expected_mesh_id=$id&display_name=http11"
http_replica=$(sed -n 's/^X-Geodex-Replica: \([^\r]*\).*/\1/p' "$tmp/http_headers.txt" | tr -d '\r')
check "an HTTP upload with its expected_mesh_id reaches ${owner[11]} (got $http_replica)" \
  test "$http_replica" = "${owner[11]}"

used=$(printf '%s\n' "${owner[@]}" | sort -u | wc -l)
check "the 12 meshes are spread over at least 2 replicas (got $used)" test "$used" -ge 2

# Kill the owner of mesh0 (SIGKILL, no drain).
victim="${owner[0]}"
victim_pid=$(awk -v n="$victim" '$1 == n {print $2}' "$tmp/cluster/pids")
kill -KILL "$victim_pid"
for _ in $(seq 1 50); do kill -0 "$victim_pid" 2>/dev/null || break; sleep 0.1; done
moved=0
for k in $(seq 0 11); do
  f="$tmp/mesh$k.off"
  now=$(replica_of "$f")
  check "after the kill, mesh$k still answers" test -n "$now"
  "$GEODEX" distances "$f" --sources 0 >"$tmp/local.txt"
  check "after the kill, mesh$k has the same answer" cmp -s "$tmp/out.txt" "$tmp/local.txt"
  if [ "${owner[$k]}" = "$victim" ]; then
    check "mesh$k moved off the killed replica" test "$now" != "$victim"
    moved=$((moved + 1))
  else
    check "mesh$k stayed on ${owner[$k]}" test "$now" = "${owner[$k]}"
  fi
  check "mesh$k: stable after the move" test "$(replica_of "$f")" = "$now"
done
check "the killed replica owned at least one mesh" test "$moved" -ge 1

finish "gateway e2e"
