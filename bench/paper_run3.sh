#!/usr/bin/env bash
# The paper's run 3 (docs/paper-runs.md, "Run 3"): one cell, shape penalty
# delta1 = 0 and delta2 = 5e4, 1e5, 2e5 (inputs/paper/shape_delta_*.yaml);
# with --hard also delta2 = 5e5 and 1e6 (the 2e5 scene with delta2 set);
# with --implicit the shape term is implicit (shape.scheme: implicit).
# Prints the equilibrium aspect ratio sqrt(I1/I2) of each run against delta2.
#
#   bench/paper_run3.sh [--hard] [--delta0] [--implicit]  (from the repository root)
#
# Environment: SOFTPACK (default build/softpack), OUT (default out/paper_run3).
# One cell on the 5120-element ellipse: about a minute per run with serial
# SuperLU on one core.
set -euo pipefail
SOFTPACK=${SOFTPACK:-build/softpack}
OUT=${OUT:-out/paper_run3}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
scheme=explicit
runs=("5e4 inputs/paper/shape_delta_5e4.yaml" "1e5 inputs/paper/shape_delta_1e5.yaml"
      "2e5 inputs/paper/shape_delta_2e5.yaml")
for arg in "$@"; do
  case $arg in
    --hard) runs+=("5e5 inputs/paper/shape_delta_2e5.yaml" "1e6 inputs/paper/shape_delta_2e5.yaml") ;;
    --delta0) runs=("0 inputs/paper/shape_delta_2e5.yaml" "${runs[@]}") ;;
    --implicit) scheme=implicit ;;
    *) echo "usage: $0 [--hard] [--delta0] [--implicit]" >&2; exit 2 ;;
  esac
done
mkdir -p "$OUT"
rows=()
for run in "${runs[@]}"; do
  set -- $run
  delta=$1 scene=$2 dir="$OUT/delta_$1"
  "$SOFTPACK" run "$scene" --out "$dir" --set shape.delta2="$delta" \
    --set shape.scheme=$scheme > "$dir.log" 2>&1 || {
    echo "delta2 = $delta: softpack failed, see $dir.log" >&2; exit 1; }
  # summary line: "N steps to t = ... (R failed attempts retried, ...)"
  steps=$(sed -n 's/^softpack: \([0-9]*\) steps.*/\1/p' "$dir.log")
  retries=$(sed -n 's/.*(\([0-9]*\) failed attempts.*/\1/p' "$dir.log")
  # cells.csv: step,t,cell,mass,xc,yc,I1,I2,angle; aspect at the end and
  # its largest change over the last 100 steps (steadiness)
  row=$(awk -F, -v last="$steps" 'NR > 1 && $1 >= last - 100 {
          a = sqrt($7 / $8); if (lo == "" || a < lo) lo = a; if (hi == "" || a > hi) hi = a
          if ($1 == last) { end = a; i1 = $7; i2 = $8 } }
        END { printf "%.4f | %.1e | %.3e | %.3e", end, hi - lo, i1, i2 }' "$dir/cells.csv")
  its=$(sed -n 's/.*), \([0-9]*\) Newton iterations.*/\1/p' "$dir.log")
  rows+=("| $delta | $row | $steps | $retries | $its |")
done
echo "shape.scheme: $scheme"
echo "| delta2 | sqrt(I1/I2) at t_end | change over the last 100 steps | I1 | I2 | steps | retries | Newton its |"
echo "|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
