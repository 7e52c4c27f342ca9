# Shared preamble of the shell tests (tests/**/*.sh): assertions, a temporary directory removed at
# exit, geodexd children on 127.0.0.1 (ports they pick) that are stopped by their PID. Sourced
# first thing, from the script's own directory, so that it works from any working directory:
#   # shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
#   source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"
# Safe under `set -u` and `set -e`. Sets $tmp and the EXIT trap: scripts add cleanup with on_exit,
# never with a trap of their own. Every wait here is bounded.
# shellcheck shell=bash

# check NAME COMMAND...: runs COMMAND; counts a pass, or a failure and prints "FAIL: NAME".
# Never stops the script: finish reports the counts.
pass=0
fail=0
check() {
  local name="$1"
  shift
  if "$@"; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    echo "FAIL: $name"
  fi
}

# expect_error NAME TEXT ARGS...: runs "$GEODEX" ARGS and checks a usage error: exit 2 and TEXT in
# what it printed on stderr (kept in $tmp/err.txt).
expect_error() {  # expect_error NAME TEXT ARGS...
  local name="$1" text="$2"
  shift 2
  "$GEODEX" "$@" >/dev/null 2>"$tmp/err.txt"
  local rc=$?
  check "$name: exit 2 ($rc)" test "$rc" -eq 2
  check "$name: says '$text'" grep -qF -- "$text" "$tmp/err.txt"
}

# finish LABEL: prints "LABEL: N passed, M failed"; its status (the script's last command) is 0
# only if no check failed.
finish() {
  echo "$1: $pass passed, $fail failed"
  [ "$fail" -eq 0 ]
}

# die MESSAGE [FILE...]: prints each FILE (logs that explain the failure), then "FAIL: MESSAGE",
# and exits 1 (for a step the rest of the script cannot run without).
die() {
  local message="$1"
  shift
  local f
  for f in "$@"; do cat "$f" 2>/dev/null; done
  echo "FAIL: $message"
  exit 1
}

# expect_code NAME CODE PATTERN ARGS...: `$GEODEX ARGS...` exits CODE with one line on stderr
# that contains PATTERN (the CLI's error contract). Three checks; stderr is left in $tmp/err.txt.
expect_code() {
  local name="$1" code="$2" pattern="$3"
  shift 3
  "$GEODEX" "$@" >/dev/null 2>"$tmp/err.txt"
  local rc=$?
  check "$name: exit $code" test $rc -eq "$code"
  check "$name: one line" test "$(wc -l <"$tmp/err.txt")" -eq 1
  check "$name: names '$pattern'" grep -q -- "$pattern" "$tmp/err.txt"
}

# $tmp: a fresh directory, removed at exit (after the on_exit commands and the geodexd stops).
tmp=$(mktemp -d) || die "mktemp -d"

# on_exit COMMAND: run COMMAND (a string, eval'd) at exit, before geodexd children are stopped and
# $tmp is removed; in the order registered.
_preamble_on_exit=()
on_exit() { _preamble_on_exit+=("$1"); }

# start_geodexd LOG [FLAG...]: starts "$GEODEXD" --listen 127.0.0.1:0 FLAG... in the background,
# stdout and stderr to LOG, with the metrics endpoint off unless a FLAG sets --metrics_listen
# (then it must be 127.0.0.1:0 too). Waits up to 30 s for the listening line (less if the child
# exits). Sets geodexd_pid, and geodexd_port (empty if it did not start; the status is then 1).
# Children still running at exit are stopped by the EXIT trap.
_preamble_geodexd_pids=()
start_geodexd() {
  local log="$1"
  shift
  local metrics=(--metrics_listen=) a
  for a in "$@"; do
    case "$a" in --metrics[-_]listen*) metrics=() ;; esac
  done
  "$GEODEXD" --listen 127.0.0.1:0 "${metrics[@]}" "$@" >"$log" 2>&1 &
  geodexd_pid=$!
  _preamble_geodexd_pids+=("$geodexd_pid")
  geodexd_port=""
  for _ in $(seq 1 300); do
    geodexd_port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$log" | head -1)
    [ -n "$geodexd_port" ] && break
    kill -0 "$geodexd_pid" 2>/dev/null || break
    sleep 0.1
  done
  [ -n "$geodexd_port" ]
}

# stop_geodexd PID [SECONDS]: SIGTERM to PID (a child started by start_geodexd), up to SECONDS
# (default 10) to drain and exit, then SIGKILL. Returns its exit status, or 124 if it had to be
# killed.
stop_geodexd() {
  local pid="$1" seconds="${2:-10}" rc=0 i
  kill -TERM "$pid" 2>/dev/null || true
  for _ in $(seq 1 $((seconds * 10))); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$pid" 2>/dev/null; then
    kill -KILL "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    rc=124
  else
    wait "$pid" 2>/dev/null || rc=$?
  fi
  # Reaped: never to be signalled again (its PID may be reused).
  for i in "${!_preamble_geodexd_pids[@]}"; do
    if [ "${_preamble_geodexd_pids[$i]}" = "$pid" ]; then unset "_preamble_geodexd_pids[$i]"; fi
  done
  return "$rc"
}

# The EXIT trap: on_exit commands, then every geodexd child still running, then $tmp. Keeps the
# script's exit status.
_preamble_cleanup() {
  local rc=$? c pid
  set +e
  for c in "${_preamble_on_exit[@]}"; do eval "$c"; done
  for pid in "${_preamble_geodexd_pids[@]}"; do stop_geodexd "$pid"; done
  rm -rf "$tmp"
  return "$rc"
}
trap _preamble_cleanup EXIT
