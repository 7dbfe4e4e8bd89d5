#!/usr/bin/env bash
# Cost of one stage of a run with full and with local supports:
# the cells of RUN_DIR's last (or given) step, as disks of their masses at
# their centres, on SCENE's mesh and model, without division or source, for
# STEPS steps of dt: seconds per step and per Newton iteration, its phases,
# unknowns and peak memory, full against local in one run of the script.
# A whole run 1 with full supports takes about an hour here (53 minutes,
# docs/local-support.md: bench/local_support.sh on run 1); this measures
# one stage, e.g. the 16-cell one, the same way for both layouts in
# minutes.
#   bench/stage_cost.sh [RUN_DIR] [SCENE] [STEPS] [DT] [STEP]
#   (defaults: out/paper/constant_volume_16 inputs/paper/constant_volume_16.yaml 3 2e-5, last step)
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
run_dir=${1:-out/paper/constant_volume_16}
scene=${2:-inputs/paper/constant_volume_16.yaml}
steps=${3:-3}
dt=${4:-2e-5}
[ -f "$run_dir/cells.csv" ] || { echo "bench/stage_cost.sh: no $run_dir/cells.csv (run bench/paper_runs.sh first)" >&2; exit 2; }
step=${5:-$(tail -1 "$run_dir/cells.csv" | cut -d, -f1)}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# the scene without its cells, then the cells of that step (radius from the
# core mass, shrunk by 0.9 so every disk lies inside the domain)
scene_without_cells "$scene" > "$tmp/stage.yaml"
echo "cells:" >> "$tmp/stage.yaml"
awk -F, -v s="$step" 'NR > 1 && $1 == s {
    printf "  - {x: %.6f, y: %.6f, radius: %.6f}\n", $5, $6, 0.9 * sqrt($10 / 3.141592653589793) }' \
  "$run_dir/cells.csv" >> "$tmp/stage.yaml"
n=$(grep -c '^  - {x:' "$tmp/stage.yaml")
t_end=$(awk -v n="$steps" -v dt="$dt" 'BEGIN { printf "%.17g", n * dt }')
echo "stage: $n cells of $run_dir at step $step on $scene; $steps steps of dt = $dt"
export OMP_NUM_THREADS=1
for mode in full local; do
  /usr/bin/time -f "%M" -o "$tmp/$mode.mem" build/softpack run "$tmp/stage.yaml" --out "$tmp/$mode" \
      --set layout.support=$mode --set division.criterion=none --set source.rate=0 \
      --set time.dt=$dt --set time.t_end=$t_end --set output.pictures=false \
      --set output.every=1000000 "${@:6}" > "$tmp/$mode.log" 2>&1 ||
    { echo "$mode run failed:"; tail -5 "$tmp/$mode.log"; exit 1; }
done
echo
echo "| supports | unknowns | steps | Newton its | s/step | s/iteration | assembly/it | factorisation/it | solves/it | peak MB | energy at the end |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for mode in full local; do
  awk -F, -v mode="$mode" -v mem="$(cat "$tmp/$mode.mem")" 'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
    $1 > 0 { k++; its += $c["newton_its"]; sec += $c["seconds"]; as += $c["assembly_s"]
             fa += $c["factorisation_s"]; so += $c["solves_s"]; u = $c["unknowns"]; e = $c["energy"] }
    END { printf "| %s | %d | %d | %d | %.3f | %.3f | %.3f | %.3f | %.3f | %.0f | %.6g |\n",
          mode, u, k, its, sec / k, sec / its, as / its, fa / its, so / its, mem / 1024, e }' \
    "$tmp/$mode/energy.csv" | tee -a "$tmp/rows"
done
awk -F'|' '{ gsub(/ /, "", $2); s[$2] = $7; i[$2] = $6 }
  END { printf "\nlocal against full: %.1fx per Newton iteration, %.1fx per step\n",
        s["full"] / s["local"], i["full"] / i["local"] }' "$tmp/rows"
