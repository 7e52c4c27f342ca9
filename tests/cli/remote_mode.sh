#!/usr/bin/env bash
# Runs a CLI test script (cli_test.sh, geometry_cli_test.sh, render_cli_test.sh) in remote mode:
# starts geodexd on 127.0.0.1 (a port it picks, no metrics port), sets GEODEX_SERVER so that every
# `geodex` command in the script goes through it, and GEODEX_MODE=remote so that the few checks of
# local-only flags (--method dijkstra, --max-windows, --threads, info --strict) are skipped.
# The script's own checks are the same in both modes. Bounded: every wait gives up.
# Usage: remote_mode.sh SCRIPT. Env: GEODEX, GEODEXD, DATA.
set -u
script="$1"
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
start_geodexd "$tmp/server.log" --data-dir "$tmp/data" --pool-threads 2 \
  --shutdown_grace_seconds 5 || die "geodexd did not start" "$tmp/server.log"
GEODEX_SERVER="127.0.0.1:$geodexd_port" GEODEX_MODE=remote bash "$script"
