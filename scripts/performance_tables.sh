#!/usr/bin/env bash
# Regenerates the tables of docs/performance.md that a script can make, at the commit they name:
# today the engine table (geodex_bench: geodex's exact engine, Dijkstra and CGAL from vertex 0 on
# every mesh of ../shared/meshes), written between the markers
#   <!-- BEGIN generated: engine -->  and  <!-- END generated: engine -->
# with the command, the commit and the date: the ICH vs Dijkstra vs CGAL table only (the run's
# other sections, the meshes and CGAL's notes, are left out: docs/performance.md stays within its
# 400 lines, scripts/check-layout.sh; ../shared/meshes/MANIFEST.md describes the meshes). Run it on a built, committed tree (it refuses
# uncommitted changes under core/ or bench/, which the figures would not describe), one benchmark
# at a time on an otherwise idle machine. Usage: scripts/performance_tables.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
bench="$build/bench/geodex_bench"
doc=docs/performance.md
[ -x "$bench" ] || { echo "performance_tables: build $bench first" >&2; exit 1; }
if ! git diff --quiet HEAD -- core bench; then
  echo "performance_tables: core/ or bench/ has uncommitted changes; commit first" >&2
  exit 1
fi
commit=$(git rev-parse --short HEAD)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
command=(--methods exact,dijkstra,cgal --sources 1 --wait-idle 30)
"$bench" "${command[@]}" --markdown "$tmp/engine.md" >"$tmp/engine.txt"
{
  echo "<!-- BEGIN generated: engine -->"
  echo "## The engine (generated at commit \`$commit\`, $(date -u +%Y-%m-%d))"
  echo
  echo "Made by \`scripts/performance_tables.sh\`, which ran, at commit \`$commit\`:"
  echo
  echo '```sh'
  echo "./$bench ${command[*]} --markdown OUT.md"
  echo '```'
  echo
  echo "Each measurement in its own process, one at a time; the first comment below says where and"
  echo "how loaded the machine was. VTP's line to beat comes from bench/data/peer_figures.tsv."
  echo
  # Before the first section (the run's comment), the engine table's section, the closing comment.
  awk '/^### /{seen = 1; keep = ($0 ~ /ICH vs Dijkstra vs CGAL/)}
       !seen || keep || /^<!-- load average/' "$tmp/engine.md" | sed -e 's/^### /### Engine: /'
  echo "<!-- END generated: engine -->"
} >"$tmp/section.md"
/usr/bin/python3 - "$doc" "$tmp/section.md" <<'PY'
import sys
doc, section = sys.argv[1], open(sys.argv[2]).read()
text = open(doc).read()
begin, end = "<!-- BEGIN generated: engine -->", "<!-- END generated: engine -->"
if begin in text:
    a = text.index(begin)
    b = text.index(end) + len(end)
    text = text[:a] + section.rstrip("\n") + text[b:]
else:  # first run: after the introduction (before the first "## " heading)
    a = text.index("\n## ") + 1
    text = text[:a] + section + "\n" + text[a:]
open(doc, "w").write(text)
PY
echo "performance_tables: wrote the engine table of $commit into $doc"
