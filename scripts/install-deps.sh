#!/usr/bin/env bash
# Installs every build and test dependency of geodex from Debian 12's packages.
# Run as root (CI and the README's set-up commands call it). Safe to run again.
set -euo pipefail

if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: run as root (apt-get needs it)" >&2
  exit 1
fi

packages=(
  # toolchain
  g++ cmake ninja-build pkgconf ccache
  # the libFuzzer tier (scripts/fuzz.sh): clang and its sanitizer/fuzzer runtimes
  clang libclang-rt-14-dev
  # the format check (scripts/check-format.sh): the tree is formatted by clang-format 14
  clang-format-14
  # runtime libraries of the service (gRPC, Protobuf, Abseil, spdlog)
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler libabsl-dev libspdlog-dev prometheus-cpp-dev
  grpc-proto
  # mesh I/O
  zlib1g-dev libpng-dev
  # SHA-256 of mesh ids (OpenSSL, already a dependency of gRPC)
  libssl-dev
  # terrain: DEMs in, rasters out, map coordinates (GDAL, and through it PROJ)
  libgdal-dev libproj-dev
  # barrier polygons cut into meshes (GEOS C API: difference, constrained Delaunay triangulation)
  libgeos-dev
  # tests and benchmarks (CGAL is a test-only reference)
  libgtest-dev libgmock-dev libbenchmark-dev libcgal-dev libgmp-dev libmpfr-dev
  # the Python client package, its example and tests (Debian's gRPC for Python; pip and venv for
  # `pip install ./client/python`)
  python3-grpcio python3-protobuf python3-pip python3-venv python3-setuptools python3-wheel
  # the terrain tests: fixtures made and outputs read back with GDAL's Python bindings
  python3-gdal python3-numpy python3-shapely
  # the Kubernetes manifest checks (tests/deploy)
  python3-yaml
  # the mesh-affine gateway (deploy/gateway) and its end-to-end test
  nginx-light
  # the quickstart's and the HTTP tests' HTTP/JSON calls
  curl
  # TLS tests make a self-signed certificate
  openssl
  # the map page of geodexd's HTTP port: Leaflet (BSD-2-Clause), built into the binary
  libjs-leaflet
)
# The map page's browser test (tests/server/map_page_test.py): headless Chromium driven by Selenium.
# GEODEX_NO_BROWSER=1 leaves them out (the Docker image's build stage runs no tests of it).
if [ -z "${GEODEX_NO_BROWSER:-}" ]; then
  packages+=(chromium chromium-driver python3-selenium)
fi

# Skip apt entirely when everything is already there (fast re-runs).
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends -o DPkg::Lock::Timeout=600 "${missing[@]}"
