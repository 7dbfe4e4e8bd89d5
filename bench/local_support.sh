#!/usr/bin/env bash
# Full against local supports on the same scene, in one run (issue 7):
# wall time and its phases, unknowns, support changes, and the agreement
# (energy at every step, cell masses and centres at the end).
#   bench/local_support.sh [SCENE] [--set k=v ...]   (default: inputs/divide_1_2_4.yaml, no noise)
# SOFTPACK=path runs another binary (a copy, so the tree can be rebuilt
# during a long run); OUT=dir keeps both runs' outputs in dir/full and
# dir/local (otherwise a temporary directory, removed at the end).
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-inputs/divide_1_2_4.yaml}
shift || true
extra=("$@")
[ ${#extra[@]} -eq 0 ] && extra=(--set noise.amplitude=0)
bin=${SOFTPACK:-build/softpack}
out=${OUT:-$(mktemp -d)}
export OMP_NUM_THREADS=1
for mode in full local; do
  sets=()
  for s in "${extra[@]}"; do sets+=("$s"); done
  /usr/bin/time -f "$mode: %e s wall, %M kB peak" "$bin" run "$scene" --out "$out/$mode" \
      --set layout.support=$mode --set output.pictures=false "${sets[@]}" 2>&1 | sed "s/^/$mode: /"
done
echo "agreement (energy.csv rows matched by step; cells at the last step):"
awk -F, 'FNR == 1 { next }
  FILENAME ~ /full/ { ef[$1] = $6; tf[$1] = $2; nf[$1] = $5; next }
  ($1 in ef) { rel = ($6 - ef[$1]) / ef[$1]; if (rel < 0) rel = -rel;
               if (rel > worst) { worst = rel; at = $1 }
               if (nf[$1] != $5) cells_differ++ }
  END { printf "  largest relative energy difference %.3e (step %d); steps with a different cell count: %d\n",
               worst, at, cells_differ + 0 }' "$out/full/energy.csv" "$out/local/energy.csv"
last=$(tail -1 "$out/full/cells.csv" | cut -d, -f1)
awk -F, -v last="$last" 'FNR == 1 || $1 != last { next }
  FILENAME ~ /full/ { m[$3] = $4; x[$3] = $5; y[$3] = $6; next }
  { dm = ($4 - m[$3]) / m[$3]; dx = $5 - x[$3]; dy = $6 - y[$3];
    printf "  cell %d: mass rel. diff %.2e, centre moved by %.2e\n", $3, dm, sqrt(dx*dx + dy*dy) }' \
  "$out/full/cells.csv" "$out/local/cells.csv"
echo "divisions (full, then local):"
cut -d, -f1-5 "$out/full/divisions.csv" | sed 's/^/  /'
cut -d, -f1-5 "$out/local/divisions.csv" | sed 's/^/  /'
[ -n "${OUT:-}" ] || rm -rf "$out"
