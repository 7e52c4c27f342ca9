#!/usr/bin/env bash
# A local geodex cluster on 127.0.0.1: N geodexd replicas (each with its own data directory) behind
# an nginx gateway that routes by the x-mesh-id metadata (deploy/gateway/nginx.conf.template).
#
#   deploy/local-cluster.sh start DIR [N]   # prints the gateway address; state and logs in DIR
#                                           # (DIR/gateway-http-address: its HTTP/JSON port)
#   deploy/local-cluster.sh stop DIR        # stops exactly the processes `start` launched
#
# Env: GEODEXD (default build/server/geodexd), NGINX (default nginx from PATH or /usr/sbin).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cmd="${1:-}"
dir="${2:-}"
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: $0 start|stop DIR [N]" >&2; exit 2; }
geodexd="${GEODEXD:-$here/../build/server/geodexd}"
nginx="${NGINX:-$(command -v nginx || echo /usr/sbin/nginx)}"

free_port() {
  /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

wait_for_port() {  # wait_for_port LOG -> prints the port geodexd reports
  local port=""
  for _ in $(seq 1 300); do
    port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$1" | head -1)
    [ -n "$port" ] && { echo "$port"; return 0; }
    sleep 0.1
  done
  echo "no listening line in $1" >&2
  return 1
}

http_port_of() {  # http_port_of LOG -> the HTTP/JSON port geodexd reports (logged before the gRPC one)
  sed -n 's|.*HTTP/JSON API on http://[0-9.]*:\([0-9]*\)/.*|\1|p' "$1" | head -1
}

case "$cmd" in
  start)
    n="${3:-3}"
    mkdir -p "$dir/gateway"
    : >"$dir/pids"
    upstreams=""
    http_upstreams=""
    gateway_port=$(free_port)
    gateway_http_port=$(free_port)
    for i in $(seq 0 $((n - 1))); do
      "$geodexd" --listen 127.0.0.1:0 --http_listen 127.0.0.1:0 \
        --http_grpc_target "127.0.0.1:$gateway_port" --data-dir "$dir/replica-$i/data" --metrics_listen "" \
        --replica_name "replica-$i" --pool-threads 1 --shutdown_grace_seconds 5 \
        >"$dir/replica-$i.log" 2>&1 &
      echo "replica-$i $!" >>"$dir/pids"
      port=$(wait_for_port "$dir/replica-$i.log")
      echo "replica-$i 127.0.0.1:$port" >>"$dir/replicas"
      upstreams+="    server 127.0.0.1:$port max_fails=1 fail_timeout=30s;"$'\n'
      http_upstreams+="    server 127.0.0.1:$(http_port_of "$dir/replica-$i.log") max_fails=1 fail_timeout=30s;"$'\n'
    done
    sed -e "s|@PREFIX@|$dir/gateway|g" -e "s|@LISTEN@|127.0.0.1:$gateway_port|" \
      -e "s|@HTTP_LISTEN@|127.0.0.1:$gateway_http_port|" "$here/gateway/nginx.conf.template" |
      awk -v u="$upstreams" -v h="$http_upstreams" \
        '{ if ($0 == "@UPSTREAMS@") printf "%s", u; else if ($0 == "@HTTP_UPSTREAMS@") printf "%s", h; else print }' \
      >"$dir/gateway/nginx.conf"
    "$nginx" -p "$dir/gateway" -c "$dir/gateway/nginx.conf" -g 'daemon off;' \
      >"$dir/gateway/stdout.log" 2>&1 &
    gateway_pid=$!
    echo "gateway $gateway_pid" >>"$dir/pids"
    for _ in $(seq 1 100); do  # until the gateway accepts connections
      (exec 3<>"/dev/tcp/127.0.0.1/$gateway_port") 2>/dev/null && break
      kill -0 "$gateway_pid" 2>/dev/null || { cat "$dir/gateway/stdout.log" >&2; exit 1; }
      sleep 0.1
    done
    echo "127.0.0.1:$gateway_port" >"$dir/gateway-address"
    echo "127.0.0.1:$gateway_http_port" >"$dir/gateway-http-address"
    cat "$dir/gateway-address"
    ;;
  stop)
    [ -f "$dir/pids" ] || exit 0
    while read -r name pid; do
      kill -TERM "$pid" 2>/dev/null || true
    done <"$dir/pids"
    while read -r name pid; do
      for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -KILL "$pid" 2>/dev/null || true
    done <"$dir/pids"
    rm -f "$dir/pids"
    ;;
  *)
    echo "usage: $0 start|stop DIR [N]" >&2
    exit 2
    ;;
esac
