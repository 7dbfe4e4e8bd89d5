#!/usr/bin/env bash
# Cost per step and per cell at a fixed number of cells ("Scale"):
# N just-born cells (radius 0.065, the aggregate's birth size) on a
# hexagonal lattice of spacing 0.15, the N sites nearest the centre of the
# 2 x 1 ellipse of inputs/aggregate_256.yaml (its mesh, model, supports and
# solver), no source and no division, STEPS steps of DT. One run per N, one
# process, OMP_NUM_THREADS=1. Complements bench/aggregate.sh (the growth
# run, whose stages differ in cell sizes, iterations and failed attempts):
# here every N starts from the same kind of packing, so the per-cell cost
# is compared at equal cell size and equal work per step.
#   bench/packed_cost.sh [STEPS] [DT] [N ...]    (defaults: 3 2e-5 16 64 256)
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
packed_args "$@"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1
echo "packed cells on inputs/aggregate_256.yaml's mesh: $steps steps of dt = $dt"
echo
echo "| cells | unknowns | unknowns / node | Newton its | s/step | s/step/cell | s/iteration | assembly/it | factorisation/it | solves/it | peak MB | per cell vs first |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
ref=""
for n in "${sizes[@]}"; do
  packed_scene "$n" "$tmp/p$n.yaml"
  /usr/bin/time -f "%M" -o "$tmp/p$n.mem" build/softpack run "$tmp/p$n.yaml" --out "$tmp/o$n" \
      "${packed_sets[@]}" --set output.pictures=false \
      > "$tmp/p$n.log" 2>&1 || { echo "$n cells: run failed"; tail -5 "$tmp/p$n.log"; exit 1; }
  nodes=$(grep -o 'NumberOfPoints="[0-9]*"' "$tmp/o$n/fields_000000.vtu" | head -1 | tr -dc 0-9)
  row=$(awk -F, -v n="$n" -v nodes="$nodes" -v mem="$(cat "$tmp/p$n.mem")" -v ref="$ref" \
    'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
     $1 > 0 { k++; its += $c["newton_its"]; sec += $c["seconds"]; as += $c["assembly_s"]
              fa += $c["factorisation_s"]; so += $c["solves_s"]
              if ($c["unknowns"] > u) u = $c["unknowns"] }
     END { per = sec / k / n
           printf "%.6g|| %d | %d | %.2f | %d | %.3f | %.4f | %.3f | %.3f | %.3f | %.3f | %.0f | %s |\n",
             per, n, u, u / nodes, its, sec / k, per, sec / its, as / its, fa / its, so / its,
             mem / 1024, ref ? sprintf("%.2f", per / ref) : "1.00" }' "$tmp/o$n/energy.csv")
  [ -z "$ref" ] && ref=${row%%||*}
  echo "|${row#*||}"
done
