#!/usr/bin/env bash
# Where a support change restores each cell's mass (layout.restore, issue
# 29): each scene run with the interior rule (the baseline: a uniform
# shift of c_k where c_k >= 1/2) and with potential (the default: one
# rise of the chemical potential over the whole support, support.c), in
# one go (bench/lib.sh ab_runs: wall time, peak memory, phases, the runs'
# agreement), then one line per scene and rule: the largest energy rise at
# a support change (relative), the largest relative mass change restored,
# the support changes, steps and failed attempts, the most unknowns.
#   bench/support_restore.sh [SCENE[@T_END][:k=v,k=v...] ...]
# Defaults: the 3D run 5 at refinements 3 (inputs/3d/embryo_8.yaml, local
# supports, the defaults otherwise), the paper's growth run
# (inputs/paper/growth_12.yaml, which pins interior) and the aggregate to
# t = 0.005 (inputs/aggregate_256.yaml, pins interior), the 2D ones with
# solver.linear=gmres_cells. NP, SOFTPACK, OUT as in bench/lib.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
specs=("$@")
[ ${#specs[@]} -gt 0 ] || specs=("inputs/3d/embryo_8.yaml:mesh.refinements=3,layout.support=local"
  "inputs/paper/growth_12.yaml:solver.linear=gmres_cells"
  "inputs/aggregate_256.yaml@0.005:solver.linear=gmres_cells")
out=${OUT:-$(mktemp -d)}
[ -n "${OUT:-}" ] || trap 'rm -rf "$out"' EXIT
echo "bench/support_restore.sh ${specs[*]}; $(date -u '+%Y-%m-%d %H:%M UTC'), NP=${NP:-1}, $(nproc --all) cores"
rows=()
for spec in "${specs[@]}"; do
  head=${spec%%:*} sets=() extra=()
  [ "$head" != "$spec" ] && IFS=, read -ra sets <<< "${spec#*:}"
  scene=${head%@*}
  [ "$head" != "$scene" ] && extra=(--set "time.t_end=${head#*@}")
  for kv in ${sets[@]+"${sets[@]}"}; do extra+=(--set "$kv"); done
  name=$(basename "$scene" .yaml)
  echo "== $spec"
  OUT=$out/$name ab_runs "$scene" interior layout.restore=interior potential \
    layout.restore=potential ${extra[@]+"${extra[@]}"}
  for rule in interior potential; do
    s=$out/$name/$rule.summary
    rows+=("$(sed -n 's/.*local supports: \([0-9]*\) changes.*restored \([0-9.e+-]*\),.*rise at a change \([0-9.e+-]*\), at most \([0-9]*\) unknowns.*/\1 \2 \3 \4/p' "$s" |
      awk -v n="$name" -v r="$rule" -v st="$(sed -n 's/.* \([0-9]*\) steps to .*(\([0-9]*\) failed.*/\1 \2/p' "$s")" \
        -v w="$(summary_wall "$rule" "$s")" \
        '{ split(st, a, " "); printf "| %s | %s | %.3g | %.3g | %d | %d | %d | %d | %.1f |", n, r, $3, $2, $1, a[1], a[2], $4, w }')")
  done
done
echo
echo "| scene | layout.restore | largest energy rise at a change | largest mass restored | changes | steps | failed attempts | unknowns (most) | wall s |"
echo "|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
