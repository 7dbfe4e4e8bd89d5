#!/usr/bin/env bash
# The iterative linear solver (solver.linear=gmres_ilu: GMRES with an
# ILU(k) preconditioner) against the direct SuperLU_DIST (the baseline), in
# one run of this script, each with its phases, Newton iterations and the
# agreement of the two runs (bench/lib.sh ab_runs):
# - N packed just-born cells (bench/lib.sh packed_scene: the aggregate's
#   mesh, model and supports, no source or division), STEPS steps of DT;
# - with GROWTH=1 also inputs/aggregate_256.yaml from one cell to t = 0.0075
#   (64 cells).
# Then one line per scene: seconds per step of each and their ratio.
# One process each (NP=2: under mpirun; GMRES then has one ILU per rank).
#   bench/krylov.sh [STEPS] [DT] [N ...]    (defaults: 3 2e-5 16 64 256)
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
packed_args "$@"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ratio_line() { # NAME DIR: seconds per step of both runs in DIR, and their ratio
  awk -F, -v name="$1" 'FNR == 1 { f++; next } $1 > 0 { s[f]++; sec[f] += $12 }
    END { a = sec[1] / s[1]; b = sec[2] / s[2]
          printf "| %s | %.3f | %.3f | %.2f |\n", name, a, b, b / a }' \
    "$2/superlu_dist/energy.csv" "$2/gmres_ilu/energy.csv" >> "$tmp/ratios"
}
for n in "${sizes[@]}"; do
  echo "== $n packed cells, $steps steps of dt = $dt"
  packed_scene "$n" "$tmp/p$n.yaml"
  OUT=$tmp/o$n ab_runs "$tmp/p$n.yaml" superlu_dist solver.linear=superlu_dist \
    gmres_ilu solver.linear=gmres_ilu "${packed_sets[@]}"
  ratio_line "$n packed cells" "$tmp/o$n"
  echo
done
if [ "${GROWTH:-0}" = 1 ]; then
  echo "== inputs/aggregate_256.yaml to t = 0.0075 (1 -> 64 cells)"
  OUT=$tmp/growth ab_runs inputs/aggregate_256.yaml superlu_dist solver.linear=superlu_dist \
    gmres_ilu solver.linear=gmres_ilu --set time.t_end=0.0075
  ratio_line "growth to 64 cells" "$tmp/growth"
  echo
fi
echo "| scene | superlu_dist s/step | gmres_ilu s/step | ratio |"
echo "|---|---|---|---|"
cat "$tmp/ratios"
