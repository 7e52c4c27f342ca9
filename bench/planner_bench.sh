#!/usr/bin/env bash
# A planner's workload (issue 56): a geodexd with default flags on 127.0.0.1 (a port it picks, no
# metrics port), then bench/planner_bench.py: 40 starts x 4 short paths per client at a 0.1 s
# timeout, from 1, 4 and 16 concurrent clients. Prints a Markdown table (docs/performance.md,
# "A planner's workload"). Bounded: the server is stopped by its PID at exit (the tests'
# preamble: start_geodexd).
# Usage: bench/planner_bench.sh [BUILD_DIR] [GRID_N]
# Env: GEODEXD, another server binary to measure with this build's client (an older commit's).
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
n="${2:-211}"
GEODEXD="${GEODEXD:-$build/server/geodexd}"
# shellcheck source=../tests/util/test_preamble.sh
source tests/util/test_preamble.sh
start_geodexd "$tmp/server.log" --data-dir "$tmp/data" || die "geodexd did not start" "$tmp/server.log"
PYTHONPATH=client/python:"$build/python" /usr/bin/python3 bench/planner_bench.py \
  "127.0.0.1:$geodexd_port" "$n"
