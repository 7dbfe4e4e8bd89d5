#!/usr/bin/env bash
# What agreement with full supports costs: runs SCENE with local
# supports at each margin (band = margin / 2) up to T_END and compares every
# run with an earlier full-support run of the same scene (FULL: its output
# directory, e.g. OUT=dir bench/local_support.sh SCENE keeps dir/full).
# Prints, per margin: wall time, the full run's seconds to the same step
# (its energy.csv), the largest unknowns, steps and Newton iterations, the
# largest relative energy difference over the steps both runs reached at
# the same t, the same at each output step, whether the cell counts agree,
# and the largest distance between the same cell's centres at the last
# step compared.
#   bench/margin_sweep.sh SCENE FULL T_END MARGIN [MARGIN ...] [-- --set k=v ...]
# SOFTPACK=path runs another binary; OUT=dir keeps the runs (dir/m<MARGIN>);
# EVERY=n tables the energy difference at the multiples of step n (25).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 4 ] || { echo "usage: bench/margin_sweep.sh SCENE FULL T_END MARGIN [MARGIN ...] [-- --set k=v ...]" >&2; exit 2; }
scene=$1 full=$2 t_end=$3
shift 3
margins=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do margins+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
[ -f "$full/energy.csv" ] || { echo "bench/margin_sweep.sh: no $full/energy.csv" >&2; exit 2; }
bin=${SOFTPACK:-build/softpack}
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
export OMP_NUM_THREADS=1
every=${EVERY:-25} # the output steps tabled: multiples of this
echo "full supports: $full (to t = $t_end)"
echo
echo "| margin (d) | band (d) | wall s | full s to the same step | unknowns (largest) | steps | Newton its | energy: largest rel. difference | at output steps | cells agree | centres: largest distance (step) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for m in "${margins[@]}"; do
  band=$(awk -v m="$m" 'BEGIN { print m / 2 }')
  dir="$out/m$m"
  start=$(date +%s.%N)
  "$bin" run "$scene" --out "$dir" --set layout.support=local --set layout.margin="$m" \
      --set layout.band="$band" --set time.t_end="$t_end" --set output.pictures=false "$@" \
      > "$dir.log" 2>&1 || { echo "margin $m: the run failed (see $dir.log)" >&2; exit 1; }
  wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
  awk -F, -v m="$m" -v band="$band" -v wall="$wall" -v every="$every" '
    FNR == 1 { next }
    FILENAME == ARGV[1] { ea[$1] = $6; ta[$1] = $2; na[$1] = $5; fs[$1] = fs[$1 - 1] + $12; next }
    FILENAME == ARGV[2] { steps = $1; its += $4; if ($18 > u) u = $18
      if (!($1 in ea)) next
      d = $2 - ta[$1]; if (d < 0) d = -d; if (d > 1e-12 * ($2 + 1e-300)) next
      rel = ($6 - ea[$1]) / ea[$1]; if (rel < 0) rel = -rel
      if (rel > worst) worst = rel
      if ($1 % every == 0) outs = outs sprintf("%s%d: %.1e", outs ? ", " : "", $1, rel)
      if (na[$1] != $5) differ++
      last = $1; next }
    FILENAME == ARGV[3] { if ($1 == last) { x[$3] = $5; y[$3] = $6 }; next }
    $1 == last && ($3 in x) { dx = $5 - x[$3]; dy = $6 - y[$3]; r = sqrt(dx * dx + dy * dy)
                              if (r > far) far = r }
    END { printf "| %s | %s | %s | %.1f | %d | %d | %d | %.2e | %s | %s | %.2e (%d) |\n",
            m, band, wall, fs[last], u, steps, its, worst, outs, differ ? "no (" differ " steps)" : "yes",
            far, last }' "$full/energy.csv" "$dir/energy.csv" "$dir/cells.csv" "$full/cells.csv"
done
[ -n "${OUT:-}" ] || rm -rf "$out"
