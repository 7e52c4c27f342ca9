#!/usr/bin/env bash
# Planner matrices (issue 19), whole CLI commands timed alike in one run: one full exact field,
# then 64 x 64 matrices between random vertices spread over the mesh and between waypoints inside
# a region of 10% of the mesh's diameter, on one core and on every usable core.
#
#   bench/planner_matrix.sh [MESH.off] [GEODEX]   (defaults: ../shared/meshes/armadillo.off,
#                                                 build/client/geodex)
# Prints a markdown table: median wall seconds of R=3 runs, and each time / the field's.
set -euo pipefail
MESH=${1:-../shared/meshes/armadillo.off}
GEODEX=${2:-build/client/geodex}
R=3
[[ -f $MESH ]] || { echo "planner_matrix.sh: no mesh $MESH" >&2; exit 2; }

# The two point sets, from the OFF file's vertices (seeded: the same points every run).
read -r SPREAD LOCAL < <(/usr/bin/python3 - "$MESH" <<'EOF'
import random, sys
f = open(sys.argv[1])
assert f.readline().strip() == "OFF"
line = f.readline()
while not line.strip() or line.startswith("#"):
    line = f.readline()
nv = int(line.split()[0])
P = [tuple(map(float, f.readline().split()[:3])) for _ in range(nv)]
lo = [min(p[k] for p in P) for k in range(3)]
hi = [max(p[k] for p in P) for k in range(3)]
diam = sum((hi[k] - lo[k]) ** 2 for k in range(3)) ** 0.5
r = random.Random(2010)
spread = r.sample(range(nv), 64)
c = P[r.randrange(nv)]
near = [i for i, p in enumerate(P) if sum((p[k] - c[k]) ** 2 for k in range(3)) ** 0.5 < 0.05 * diam]
local = r.sample(near, 64)
print(",".join(map(str, spread)), ",".join(map(str, local)))
EOF
)

median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
timed() {  # prints the median wall seconds of R runs of "$@"
  for _ in $(seq $R); do
    local s e
    s=$(date +%s.%N)
    "$@" >/dev/null 2>&1
    e=$(date +%s.%N)
    echo "$e - $s" | bc -l
  done | median
}

CORES=$(nproc)
FIELD=$(timed "$GEODEX" distances "$MESH" --sources 0)
echo "mesh: $MESH; $CORES usable core(s); commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
echo
echo "| command | threads | wall s | / one field |"
echo "|---|---:|---:|---:|"
printf '| one full field (distances --sources 0) | 1 | %.3f | 1.00 |\n' "$FIELD"
for set in spread local; do
  points=$SPREAD
  [[ $set == local ]] && points=$LOCAL
  for threads in 1 "$CORES"; do
    t=$(timed "$GEODEX" matrix "$MESH" --sources "$points" --targets "$points" --threads "$threads")
    printf '| 64 x 64 %s | %s | %.3f | %.2f |\n' "$set" "$threads" "$t" "$(echo "$t / $FIELD" | bc -l)"
  done
done
