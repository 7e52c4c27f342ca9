#!/usr/bin/env bash
# Records the engine's work (windows created and processed) on a fixed set of (mesh, sources,
# options) cases into tests/data/window_counts.tsv, which WindowCountGuardTest reads: a pruning
# regression that makes any case create more than 2% more windows fails that test. Rerun this
# (and commit the file, which names the commit it was recorded at) when a change lowers the counts
# on purpose. Usage: scripts/window_counts.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
geodex="${1:-build}/client/geodex"
out=tests/data/window_counts.tsv
cases=(
  "kitten.off exact 0 0"
  "kitten.off exact 0 0,1234"
  "kitten.off ich 0 0"
  "kitten.off exact 0.3 0"
  "bunny-npm.off exact 0 17"
  "bunny-npm.off exact 0 e:0:1:0.5"
  "fertility.off exact 0 0"
  "fertility.off ich 0 100"
  "bump-domain.off exact 0 0"
  "bump-domain.off exact 0 f:10:0.2:0.3:0.5"
  "three-peaks.off exact 0 0"
  "knight.off exact 0 0"
)
{
  echo "# Windows per case, recorded at commit $(git rev-parse --short HEAD) by scripts/window_counts.sh."
  echo "# WindowCountGuardTest fails when a case creates more than 2% more windows than recorded here."
  printf '# mesh\tmethod\tlambda\tsources\twindows_created\twindows_processed\n'
  for c in "${cases[@]}"; do
    read -r mesh method lambda sources <<<"$c"
    stats=$("$geodex" distances "tests/data/$mesh" --sources "$sources" --method "$method" \
      --lambda "$lambda" --stats --output /dev/null 2>&1 >/dev/null | tail -1)
    created=$(sed -n 's/.*"windows_created": \([0-9]*\).*/\1/p' <<<"$stats")
    processed=$(sed -n 's/.*"windows_processed": \([0-9]*\).*/\1/p' <<<"$stats")
    printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$mesh" "$method" "$lambda" "$sources" "$created" "$processed"
  done
} >"$out"
echo "wrote $out"
