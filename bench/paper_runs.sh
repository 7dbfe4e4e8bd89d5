#!/usr/bin/env bash
# Reruns the paper's runs 1, 2 and 5 and prints, per run, the
# table of docs/paper-runs.md; copies the pictures at each stage (the last
# picture with N cells, for every N reached) and the energy curve to
# docs/img/paper/<run>/.
#   bench/paper_runs.sh [--reuse] [run ...]
#   runs: constant_volume_16 growth_12 embryo_8 growth_shape_12 (the paper's run 4;
#   with run 2 it prints the comparison of the two), and on request
#   growth_shape_strong_12 and growth_shape_implicit_12 (run 4 with stronger
#   penalties, the latter with the implicit term; added to the comparison),
#   growth_calibrated_12 and growth_shape_calibrated_12 (runs 2 and 4 on the
#   seed calibrated for the paper's moduli: docs/paper-runs.md)
# --reuse: do not rerun a run whose out/paper/<run>/ and out/paper/<run>.log
# exist (tables and pictures from that earlier run).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
reuse=0
[ "${1:-}" = "--reuse" ] && { reuse=1; shift; }
runs=("$@")
[ ${#runs[@]} -eq 0 ] && runs=(constant_volume_16 growth_12 embryo_8 growth_shape_12)
export OMP_NUM_THREADS=1
for run in "${runs[@]}"; do
  out=out/paper/$run
  if [ $reuse -eq 0 ] || [ ! -f "$out.log" ] || [ ! -f "$out/energy.csv" ]; then
    rm -rf "$out"
    mkdir -p out/paper
    build/softpack run "inputs/paper/$run.yaml" --out "$out" > "$out.log" 2>&1
  fi
  echo "== $run (inputs/paper/$run.yaml)"
  grep '^softpack:' "$out.log" | grep -v 'is due to divide' | sed 's/^/   /'
  # final cells, steps, Newton iterations
  awk -F, 'NR > 1 { n = $5; steps = $1; its += $4 } END {
      printf "   final cells %d, steps %d, Newton iterations %d\n", n, steps, its }' "$out/energy.csv"
  # total cell mass drift and each cell against the mean at the end
  awk -F, 'NR == 1 { next } { m[$1] += $4; last = $1 } $1 == 0 { m0 += $4 }
    { cell[$1, $3] = $4; core[$1, $3] = $10; ncell[$1] = ($3 > ncell[$1] ? $3 : ncell[$1]) }
    END { n = ncell[last]; mean = m[last] / n; worst = 0; core_mean = 0
      for (k = 1; k <= n; ++k) { d = cell[last, k] / mean - 1; if (d < 0) d = -d; if (d > worst) worst = d; core_mean += core[last, k] / n }
      drift = (m[last] - m0) / m0; if (drift < 0) drift = -drift
      printf "   total cell mass %.10g -> %.10g (relative change %.2e); largest deviation of a cell from the mean mass %.1f%%\n",
             m0, m[last], drift, 100 * worst
      if (core_mean > 0) { worst = 0
        for (k = 1; k <= n; ++k) { d = core[last, k] / core_mean - 1; if (d < 0) d = -d; if (d > worst) worst = d }
        printf "   largest deviation of a cell'"'"'s core mass (c >= 0.05) from the mean %.1f%%\n", 100 * worst } }' "$out/cells.csv"
  # growth runs: the step after which the total cell mass stays constant
  # (every source off) and whether the energy then decreases monotonically
  if grep -q '^source:.*rate: *[1-9]' "inputs/paper/$run.yaml"; then
    off=$(awk -F, 'NR > 1 { m[$1] += $4; last = $1 } END {
        s = last; while (s > 0 && (s - 1) in m && (m[s - 1] - m[last])^2 <= (1e-12 * m[last])^2) --s; print s }' "$out/cells.csv")
    awk -F, -v off="$off" 'NR > 1 && $1 >= off { if (seen && $6 > prev) { ++rises; if ($6 - prev > worst) worst = $6 - prev }
        prev = $6; seen = 1; ++n }
      END { printf "   sources off from step %d on (total mass constant after it); energy over the %d steps since: %s\n",
            off, n, rises ? sprintf("rises %d times (largest %.3g)", rises, worst) : "decreases monotonically" }' "$out/energy.csv"
  fi
  echo "   divisions (t, step, parent, child, axis angle):"
  awk -F, 'NR > 1 { printf "     %.5f  %4d  %2d -> %2d  %+.3f\n", $1, $2, $3, $4, $5 }' "$out/divisions.csv"
  # pictures at each stage
  img=docs/img/paper/$run
  rm -rf "$img"
  stage_pictures "$out" "$img" 2
  echo "   pictures: $(ls "$img" | tr '\n' ' ')"
done

# Run 4 against run 2: the energy, the spikes at the divisions
# and the packing at the end. Spike of a division at step S: height
# (peak - e0) / e0 with e0 the energy of step S-1 and the peak the largest
# energy before the next division; width: time from step S-1 until the
# energy is back to e0 + half the height (">" if the next division came first).
# Packing: the cells' aspect ratios sqrt(I1/I2), and the area inside their
# membranes (cells.csv's area, c_k >= 1/2) over Omega's, pi semi_x semi_y.
if [ -f out/paper/growth_12/cells.csv ] && [ -f out/paper/growth_shape_12/cells.csv ]; then
  echo "== run 4 (shape penalty) against run 2"
  echo "   | run | cells | final energy (shape part) | largest energy | mean spike height | mean spike width | mean sqrt(I1/I2) | largest sqrt(I1/I2) | interiors / Omega |"
  # (also out/paper/growth_shape_12_implicit and growth_shape_implicit_2e5
  # when present: the commands are in docs/paper-runs.md)
  for run in growth_12 growth_shape_12 growth_shape_strong_12 growth_shape_implicit_12 \
             growth_shape_12_implicit growth_shape_implicit_2e5 \
             growth_calibrated_12 growth_shape_calibrated_12; do
    out=out/paper/$run
    [ -f "$out/cells.csv" ] || continue
    e=$(awk -F, 'NR > 1 { last = $6; shape = $11; if ($6 > peak) peak = $6 } END { printf "%.4g (%.3g) | %.4g", last, shape, peak }' "$out/energy.csv")
    spikes=$(awk -F, 'FNR == 1 { next }
      FILENAME ~ /divisions/ { if (!($2 in div)) { div[$2] = 1; ds[++nd] = $2 } next }
      { t[$1] = $2; en[$1] = $6; last = $1 }
      END { for (i = 1; i <= nd; ++i) { s = ds[i]; e0 = en[s - 1]; stop = i < nd ? ds[i + 1] - 1 : last
              peak = e0; at = s
              for (j = s; j <= stop; ++j) if (en[j] > peak) { peak = en[j]; at = j }
              w = -1
              for (j = at; j <= stop; ++j) if (en[j] - e0 <= (peak - e0) / 2) { w = t[j] - t[s - 1]; break }
              if (w < 0) { w = t[stop] - t[s - 1]; open++ }
              h += (peak - e0) / e0; wsum += w }
            printf "%.3g | %.3g%s", h / nd, wsum / nd, open ? sprintf(" (%d of %d >)", open, nd) : "" }' \
      "$out/divisions.csv" "$out/energy.csv")
    a=$(awk -F, 'NR > 1 { last = $1; if ($8 > 0) r[$1, $3] = sqrt($7 / $8); n[$1] = $3 > n[$1] ? $3 : n[$1] }
      END { s = 0; m = 0; for (k = 1; k <= n[last]; ++k) { s += r[last, k]; if (r[last, k] > m) m = r[last, k] }
            printf "%d | %.3f | %.3f", n[last], s / n[last], m }' "$out/cells.csv")
    cells=${a%% *}
    # every run-4 variant has run 2's mesh
    omega=$(sed -n 's/.*semi_x: *\([0-9.e+-]*\), *semi_y: *\([0-9.e+-]*\).*/\1 \2/p' \
      inputs/paper/growth_12.yaml | awk '{ printf "%.10g", 3.14159265358979 * $1 * $2 }')
    covered=$(awk -F, -v omega="$omega" 'NR == 1 { has = $11 == "area"; next }
      { last = $1; area[$1] += $11 } END { if (has) printf "%.3f", area[last] / omega; else printf "-" }' \
      "$out/cells.csv")
    echo "   | $run | $cells | $e | $spikes | ${a#* | } | $covered |"
  done
fi
