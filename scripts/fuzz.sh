#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang and runs each for a bounded time on a copy of
# its committed seed corpus (tests/fuzz/corpus/<name>; new inputs stay in the copy).
#   bash scripts/fuzz.sh [SECONDS_PER_TARGET=60] [TARGET...]
# A crash, a leak, a timeout (one input over 25 s) or an out-of-memory (over 2 GiB) fails the run;
# the input is saved under build-fuzz/artifacts/ and the report printed. Fix it, then add the input
# to the target's corpus directory so it stays fixed.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(mesh_reader_fuzzer request_fuzzer stored_mesh_fuzzer dem_fuzzer http_fuzzer)

# -g1: line tables are all a report needs, and full debug info doubles the compile time.
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DGEODEX_FUZZ=ON -DGEODEX_BUILD_TESTS=OFF -DGEODEX_BUILD_BENCH=OFF >/dev/null
ninja -C build-fuzz -j "$(nproc)" "${targets[@]}"

mkdir -p build-fuzz/artifacts
status=0
for target in "${targets[@]}"; do
  name=${target%_fuzzer}
  work=build-fuzz/corpus/$name
  rm -rf "$work" && mkdir -p "$work"
  cp tests/fuzz/corpus/"$name"/* "$work"/
  log=build-fuzz/$target.log
  echo "--- $target: ${seconds} s on $(ls tests/fuzz/corpus/"$name" | wc -l) seeds"
  # -close_fd_mask=2: Protobuf logs every invalid UTF-8 string it parses; libFuzzer keeps its own
  # output and the sanitizers' reports on a duplicate of stderr.
  if UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     ./build-fuzz/tests/fuzz/"$target" "$work" -max_total_time="$seconds" -timeout=25 \
       -rss_limit_mb=2048 -close_fd_mask=2 -print_final_stats=1 \
       -artifact_prefix=build-fuzz/artifacts/"$name"- >"$log" 2>&1; then
    grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb|stat::new_units_added)' "$log" || true
    grep -E '#[0-9]+[[:space:]]+DONE' "$log" | tail -1 || true
  else
    status=1
    echo "FAILED: $target (log $log; input in build-fuzz/artifacts/)"
    tail -n 60 "$log"
  fi
done
exit $status
