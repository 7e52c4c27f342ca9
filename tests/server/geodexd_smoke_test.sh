#!/usr/bin/env bash
# The geodexd binary as an operator runs it: starts on 127.0.0.1 (a port it picks), reports
# where it listens (flags spelled with dashes or underscores), and on SIGTERM drains and exits 0;
# settings that cannot work make it exit 1 naming the flag. Bounded: gives up after 30 s.
# Env: GEODEXD (the binary), VERSION (CMake's project version).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
check "--version prints CMake's project version" test "$("$GEODEXD" --version)" = "geodexd ${VERSION:-?}"
# Every socket on a port of its own (port 0): a quickstart server may hold the default ports.
# start_geodexd adds --listen 127.0.0.1:0 and waits up to 30 s for the listening line.
start_geodexd "$tmp/log" --metrics_listen 127.0.0.1:0 --data-dir "$tmp/data" \
  --pool-threads 1 --shutdown_grace_seconds 2
port=$geodexd_port
check "reports a listening port" test -n "$port"
check "the port is open on 127.0.0.1" bash -c "exec 3<>/dev/tcp/127.0.0.1/$port"
# The client library's example (it links geodex_client alone): a path on a mesh file it uploads.
if [ -n "${PATH_CLIENT:-}" ]; then
  "$PATH_CLIENT" "127.0.0.1:$port" "$DATA/kitten.off" 0 1000 >"$tmp/path.txt" 2>&1
  check "the client example answers a path" test $? -eq 0
  check "its length is positive and its points end at the vertices" /usr/bin/python3 - "$tmp/path.txt" <<'PY'
import sys
rows = open(sys.argv[1]).read().split("\n")
length = float(rows[0].split()[1].rstrip(","))
points = [r.split() for r in rows[1:] if r.strip()]
assert length > 0 and len(points) >= 2, rows[:3]
assert {points[0][3], points[-1][3]} == {"0", "1000"}, (points[0], points[-1])
PY
fi
stop_geodexd "$geodexd_pid" 30  # up to 30 s to drain and exit (124 if it had not)
rc=$?
check "SIGTERM exits 0" test "$rc" -eq 0
check "logs the shutdown" grep -q "shutting down" "$tmp/log"
# Settings that cannot work: exit 1 at once with one line naming the flag, never a crash.
for bad in --pool_threads=100000 --stream_chunk_bytes=0 --mesh_budget_bytes=0 \
           --shutdown_grace_seconds=-5 --max_receive_message_bytes=0; do
  flag=${bad%%=*}
  timeout 30 "$GEODEXD" --listen 127.0.0.1:0 --metrics_listen= --samples=false "$bad" \
    >"$tmp/bad.log" 2>&1
  rc=$?
  check "$bad exits 1" test "$rc" -eq 1
  check "$bad is named in the error" grep -q -- "$flag" "$tmp/bad.log"
done
finish "geodexd smoke"
