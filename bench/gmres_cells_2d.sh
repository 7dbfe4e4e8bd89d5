#!/usr/bin/env bash
# gmres_cells (GMRES on the cells' diagonal blocks, the 3D default) against
# MUMPS (the 2D default, the baseline) on 2D scenes, before making it the
# 2D default too: each scene run twice in one go (bench/lib.sh
# ab_runs: wall time, peak memory, phases, Newton iterations,
# factorisations, failed attempts, the runs' agreement), then one line per
# scene with both wall times and their ratio.
#   bench/gmres_cells_2d.sh [SCENE[@T_END] ...]
# Defaults: inputs/default.yaml (3 cells relaxing), inputs/paper/embryo_8.yaml
# (run 5: 1 -> 8 cells by division, local supports), inputs/paper/growth_12.yaml
# (growth with a source) and inputs/aggregate_256.yaml@0.0075 (1 -> 64
# cells, local supports). NP=2 runs each on two processes.
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(inputs/default.yaml inputs/paper/embryo_8.yaml
  inputs/paper/growth_12.yaml inputs/aggregate_256.yaml@0.0075)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "bench/gmres_cells_2d.sh ${scenes[*]}; $(date -u '+%Y-%m-%d %H:%M UTC'), NP=${NP:-1}, $(nproc --all) cores"
rows=()
for spec in "${scenes[@]}"; do
  scene=${spec%@*} extra=()
  [ "$spec" != "$scene" ] && extra=(--set "time.t_end=${spec#*@}")
  name=$(basename "$scene" .yaml)
  echo "== $spec"
  OUT=$tmp/$name ab_runs "$scene" mumps solver.linear=mumps gmres_cells solver.linear=gmres_cells \
    "${extra[@]}"
  a=$(summary_wall mumps "$tmp/$name/mumps.summary")
  b=$(summary_wall gmres_cells "$tmp/$name/gmres_cells.summary")
  rows+=("$(awk -v n="$spec" -v a="$a" -v b="$b" 'BEGIN { printf "| %s | %.1f | %.1f | %.2f |", n, a, b, b / a }')")
done
echo
echo "| scene | mumps s | gmres_cells s | gmres_cells / mumps |"
echo "|---|---|---|---|"
printf '%s\n' "${rows[@]}"
