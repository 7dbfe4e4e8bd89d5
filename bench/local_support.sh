#!/usr/bin/env bash
# Full against local supports on the same scene, in one run:
# wall time and its phases, unknowns, support changes, and the agreement
# (energy at every step, cell masses and centres at the end).
#   bench/local_support.sh [SCENE] [--set k=v ...]   (default: inputs/divide_1_2_4.yaml, no noise)
# SOFTPACK=path runs another binary (a copy, so the tree can be rebuilt
# during a long run); OUT=dir keeps both runs' outputs in dir/full and
# dir/local (otherwise a temporary directory, removed at the end).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
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
compare_runs "$out/full" "$out/local"
[ -n "${OUT:-}" ] || rm -rf "$out"
