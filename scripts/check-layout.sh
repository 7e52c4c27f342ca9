#!/usr/bin/env bash
# Fails when the tree outgrows the layout it promises (docs/architecture.md, issue 55):
#   - a product C++ file (core, terrain, server, client, proto/convert) over 1,000 lines;
#   - docs/performance.md over 400 lines (current figures; the history is in docs/history.md);
#   - a docs/status.md row over 400 characters (one or two sentences a row).
# .ci/run calls it with the format check; ctest runs it as layout_checks.
set -euo pipefail
cd "$(dirname "$0")/.."
fail=0
while read -r lines file; do
  if [ "$file" != total ] && [ "$lines" -gt 1000 ]; then
    echo "check-layout: $file has $lines lines (at most 1,000 for a product file: split it by concern)" >&2
    fail=1
  fi
done < <(git ls-files 'core/*.cc' 'core/*.h' 'terrain/*.cc' 'terrain/*.h' 'server/*.cc' 'server/*.h' \
  'client/*.cc' 'client/*.h' 'proto/convert/*.cc' 'proto/convert/*.h' | xargs wc -l)
perf=$(wc -l <docs/performance.md)
if [ "$perf" -gt 400 ]; then
  echo "check-layout: docs/performance.md has $perf lines (at most 400: move history to docs/history.md)" >&2
  fail=1
fi
while IFS= read -r row; do
  echo "check-layout: a docs/status.md row has ${#row} characters (at most 400): ${row:0:60}..." >&2
  fail=1
done < <(awk 'length($0) > 400 && /^\|/' docs/status.md)
[ "$fail" -eq 0 ] && echo "check-layout: product files, docs/performance.md and docs/status.md within their limits"
exit "$fail"
