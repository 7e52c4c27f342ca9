#!/usr/bin/env bash
# The installed package as a planner's project sees it (docs/install.md): `cmake --install` into a
# temporary prefix; examples/planner_cpp copied outside the tree and built against that prefix alone
# (GDAL disabled, so nothing can reach the terrain library), as a shared library linking the client
# plus a program; the same sources built with pkg-config; both run against the installed geodexd.
# Env: BUILD (the build directory), SRC (the source tree), DATA (tests/data).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
prefix="$tmp/prefix"

cmake --install "$BUILD" --prefix "$prefix" >"$tmp/install.log" 2>&1 || die "cmake --install" "$tmp/install.log"
check "installs geodex and geodexd" test -x "$prefix/bin/geodex" -a -x "$prefix/bin/geodexd"
check "installs the client's header" test -f "$prefix/include/geodex/geodex_client.h"
check "installs core's headers" test -f "$prefix/include/geodex/geodesic_solver.h"
check "installs the CMake package" test -f "$prefix/lib/cmake/geodex/geodexConfig.cmake"
check "installs geodex.pc" test -f "$prefix/lib/pkgconfig/geodex.pc"
check "no CLI internals or generated API among the headers" \
  bash -c "! find '$prefix/include' -name 'cli_*' -o -name '*.pb.h' | grep -q ."
check "the installed headers name no generated type" bash -c "! grep -rq 'v1::' '$prefix/include'"
missing=$(grep -rhoE '#include "geodex/[^"]+"' "$prefix/include" | sed -E 's/#include "(.*)"/\1/' | sort -u |
  while read -r h; do test -f "$prefix/include/$h" || echo "$h"; done)
check "every geodex header the installed headers include is installed${missing:+ (missing: $missing)}" test -z "$missing"

# The example, copied away from the tree: only the prefix can satisfy find_package(geodex).
cp -r "$SRC/examples/planner_cpp" "$tmp/planner_src"
cmake -S "$tmp/planner_src" -B "$tmp/planner_build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_DISABLE_FIND_PACKAGE_GDAL=ON >"$tmp/configure.log" 2>&1 ||
  die "configure examples/planner_cpp against the prefix" "$tmp/configure.log"
cmake --build "$tmp/planner_build" -j 2 >"$tmp/build.log" 2>&1 || die "build examples/planner_cpp" "$tmp/build.log"
check "the planner library is a shared object" test -f "$tmp/planner_build/libplanner.so"
check "the planner links no GDAL" bash -c "! ldd '$tmp/planner_build/libplanner.so' | grep -qiE 'gdal|libproj|geos'"

# pkg-config: the same sources, one compiler command, as C++17 (the headers need no more, and
# geodex.pc forces no -std on its users).
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
check "geodex.pc sets no -std" bash -c "! pkg-config --cflags geodex | grep -q -- -std="
# shellcheck disable=SC2046
g++ -std=c++17 -O1 -o "$tmp/planner_pc" "$tmp/planner_src/main.cc" "$tmp/planner_src/planner.cc" \
  $(pkg-config --cflags --libs geodex) >"$tmp/pc.log" 2>&1
check "builds with pkg-config --cflags --libs geodex" test $? -eq 0

GEODEXD="$prefix/bin/geodexd"
start_geodexd "$tmp/server.log" --data-dir "$tmp/data" --pool-threads 2 ||
  die "the installed geodexd did not start" "$tmp/server.log"
expected=$("$prefix/bin/geodex" path "$DATA/kitten.off" --from 0 --to 1000 --format json |
  /usr/bin/python3 -c 'import json, sys; print("%.17g" % json.load(sys.stdin)["length"])')
for planner in "$tmp/planner_build/planner_cpp" "$tmp/planner_pc"; do
  name=$(basename "$planner")
  "$planner" "127.0.0.1:$geodexd_port" "$DATA/kitten.off" 0 1000 >"$tmp/$name.out" 2>&1
  check "$name exits 0" test $? -eq 0
  check "$name: the exact length alone on line 1, the CLI's to the bit" \
    test "$(head -1 "$tmp/$name.out")" = "$expected"
  check "$name: the path's simplices, a 3 x 3 matrix and 2 nearest" \
    bash -c "grep -q '^path: ' '$tmp/$name.out' && grep -q '^matrix 3 x 3' '$tmp/$name.out' && grep -q '^2 nearest' '$tmp/$name.out'"
  check "$name: a too-short deadline is DEADLINE_EXCEEDED, the next call answers" \
    bash -c "grep -q 'DEADLINE_EXCEEDED' '$tmp/$name.out' && grep -q '^deadline 60 s: 2500 distances' '$tmp/$name.out'"
  check "$name: the async path has the same length; the cancelled call answers" \
    bash -c "grep -q '^async path: the same length' '$tmp/$name.out' && grep -qE '^cancelled: (CANCELLED|answered first)' '$tmp/$name.out'"
done
finish "install"
