#!/usr/bin/env bash
# Builds the geodex image and checks it as an operator would: the container runs on the host
# network bound to 127.0.0.1 (dockerd runs with --bridge=none: no bridge network is used), its
# HEALTHCHECK reaches "healthy", a real query through the CLI answers, and `docker stop` is quick
# and clean (exit code 0). Needs root and docker.io; builds an offline debian:bookworm base with
# debootstrap when the image is missing (base images cannot be pulled here). Starts dockerd if it is
# not running and stops it again (by PID). Bounded: every wait gives up.
#
#   bash deploy/docker-smoke.sh            (from the repository root)
set -euo pipefail
cd "$(dirname "$0")/.."
tag="geodex:smoke"
work=$(mktemp -d)
started_dockerd=""
container=""
cleanup() {
  [ -n "$container" ] && docker rm -f "$container" >/dev/null 2>&1 || true
  if [ -n "$started_dockerd" ]; then
    kill -TERM "$started_dockerd" 2>/dev/null || true
    for _ in $(seq 1 100); do kill -0 "$started_dockerd" 2>/dev/null || break; sleep 0.1; done
    umount /run/docker/netns/default 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT
step() { echo "=== docker smoke: $* ($(date +%T))"; }

if ! docker info >/dev/null 2>&1; then
  step "starting dockerd (--bridge=none --iptables=false)"
  dockerd --bridge=none --iptables=false >"$work/dockerd.log" 2>&1 &
  started_dockerd=$!
  for _ in $(seq 1 100); do docker info >/dev/null 2>&1 && break; sleep 0.2; done
  docker info >/dev/null 2>&1 || { cat "$work/dockerd.log"; exit 1; }
fi

if ! docker image inspect debian:bookworm >/dev/null 2>&1; then
  step "building an offline debian:bookworm base with debootstrap"
  mirror=$(sed -n 's/^URIs: *\(http[^ ]*debian\)$/\1/p' /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -1)
  mirror="${mirror:-http://deb.debian.org/debian}"
  debootstrap --variant=minbase bookworm "$work/rootfs" "$mirror" >"$work/debootstrap.log" 2>&1 ||
    { tail -20 "$work/debootstrap.log"; exit 1; }
  cat >"$work/rootfs/etc/apt/sources.list" <<SOURCES
deb $mirror bookworm main
deb $mirror bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
SOURCES
  echo force-unsafe-io >"$work/rootfs/etc/dpkg/dpkg.cfg.d/unsafe-io"
  tar -C "$work/rootfs" -c . | docker import - debian:bookworm >/dev/null
  rm -rf "$work/rootfs"
fi

step "docker build (geodexd and geodex; GEODEX_TESTS=ON would run the suite too)"
docker build --network host -t "$tag" . >"$work/build.log" 2>&1 || { tail -40 "$work/build.log"; exit 1; }
size=$(docker image inspect "$tag" --format '{{.Size}}')
echo "image $tag: $((size / 1024 / 1024)) MiB"

port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
http_port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
step "docker run on the host network, 127.0.0.1:$port (HTTP/JSON on $http_port)"
container=$(docker run -d --network host \
  --health-cmd "geodex --server 127.0.0.1:$port health" --health-interval 1s --health-start-period 30s \
  "$tag" --listen="127.0.0.1:$port" --http_listen="127.0.0.1:$http_port" --metrics_listen= \
  --shutdown_grace_seconds=5)
health=""
for _ in $(seq 1 120); do
  health=$(docker inspect "$container" --format '{{.State.Health.Status}}')
  [ "$health" = "healthy" ] && break
  sleep 1
done
echo "health: $health"
[ "$health" = "healthy" ] || { docker logs "$container"; exit 1; }
user=$(docker exec "$container" id -u)
echo "runs as uid $user"
[ "$user" != "0" ] || { echo "the container runs as root"; exit 1; }

answer=$(docker exec "$container" geodex --server "127.0.0.1:$port" path terrain --from 0 --to 4224)
answer="${answer%%$'\n'*}"  # the length (line 1)
echo "path terrain 0 -> 4224 through the container: $answer"
local_answer=$(./build/client/geodex path sample:terrain --from 0 --to 4224 2>/dev/null || true)
local_answer="${local_answer%%$'\n'*}"
if [ -n "$local_answer" ]; then
  [ "$answer" = "$local_answer" ] || { echo "differs from local mode: $local_answer"; exit 1; }
fi
[ -n "$answer" ] || exit 1
http_answer=$(curl -sf -X POST -H 'Content-Type: application/json' \
  "http://127.0.0.1:$http_port/v1/meshes/terrain:findShortestPath" \
  -d '{"from": {"vertex": 0}, "to": {"vertex": 4224}}' |
  /usr/bin/python3 -c 'import json, sys; print(json.load(sys.stdin)["distance"])')
echo "the same path over HTTP/JSON: $http_answer"
[ -n "$http_answer" ] || { docker logs "$container" | tail -5; exit 1; }

step "docker stop"
start=$(date +%s)
docker stop --time 30 "$container" >/dev/null
took=$(( $(date +%s) - start ))
code=$(docker inspect "$container" --format '{{.State.ExitCode}}')
echo "docker stop took ${took}s, exit code $code"
[ "$code" = "0" ] || { docker logs "$container" | tail -5; exit 1; }
[ "$took" -lt 20 ] || { echo "docker stop was not quick"; exit 1; }
docker logs "$container" 2>&1 | grep -q "geodexd stopped" || { echo "no clean shutdown line"; exit 1; }
echo "docker smoke: passed"
