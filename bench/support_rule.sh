#!/usr/bin/env bash
# A support rule against another: each scene run with
# --set KEY=BASE (the baseline) and --set KEY=NEW, in one go
# (bench/lib.sh ab_runs: wall time, peak memory, phases, the runs'
# agreement), then one line per scene and value: the largest energy rise
# at a support change (relative), the largest relative mass change
# restored, the support changes, steps and failed attempts, the most
# unknowns.
#   bench/support_rule.sh KEY BASE NEW [SCENE[@T_END][:k=v,k=v...] ...]
# e.g. bench/support_rule.sh layout.restore interior potential
#      (bench/support_restore.sh), layout.buffer_elements margin whole.
# Default scenes: the 3D run 5 at refinements 3 (inputs/3d/embryo_8.yaml,
# local supports, the defaults otherwise), the paper's growth run
# (inputs/paper/growth_12.yaml, which pins the published rules) and the
# aggregate to t = 0.005 (inputs/aggregate_256.yaml, the same), the 2D
# ones with solver.linear=gmres_cells; KEY is set in all of them. NP,
# SOFTPACK, OUT as in bench/lib.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
[ $# -ge 3 ] || { echo "usage: $0 KEY BASE NEW [SCENE[@T_END][:k=v,...] ...]" >&2; exit 2; }
key=$1 base=$2 new=$3
shift 3
specs=("$@")
[ ${#specs[@]} -gt 0 ] || specs=("inputs/3d/embryo_8.yaml:mesh.refinements=3,layout.support=local"
  "inputs/paper/growth_12.yaml:solver.linear=gmres_cells"
  "inputs/aggregate_256.yaml@0.005:solver.linear=gmres_cells")
out=${OUT:-$(mktemp -d)}
[ -n "${OUT:-}" ] || trap 'rm -rf "$out"' EXIT
echo "bench/support_rule.sh $key $base $new ${specs[*]}; $(date -u '+%Y-%m-%d %H:%M UTC'), NP=${NP:-1}, $(nproc --all) cores"
rows=()
for spec in "${specs[@]}"; do
  head=${spec%%:*} sets=() extra=()
  [ "$head" != "$spec" ] && IFS=, read -ra sets <<< "${spec#*:}"
  scene=${head%@*}
  [ "$head" != "$scene" ] && extra=(--set "time.t_end=${head#*@}")
  for kv in ${sets[@]+"${sets[@]}"}; do extra+=(--set "$kv"); done
  name=$(basename "$scene" .yaml)
  echo "== $spec"
  OUT=$out/$name ab_runs "$scene" "$base" "$key=$base" "$new" "$key=$new" \
    ${extra[@]+"${extra[@]}"}
  for rule in "$base" "$new"; do
    s=$out/$name/$rule.summary
    rows+=("$(sed -n 's/.*local supports: \([0-9]*\) changes.*restored \([0-9.e+-]*\),.*rise at a change \([0-9.e+-]*\), at most \([0-9]*\) unknowns.*/\1 \2 \3 \4/p' "$s" |
      awk -v n="$name" -v r="$rule" -v st="$(sed -n 's/.* \([0-9]*\) steps to .*(\([0-9]*\) failed.*/\1 \2/p' "$s")" \
        -v w="$(summary_wall "$rule" "$s")" \
        '{ split(st, a, " "); printf "| %s | %s | %.3g | %.3g | %d | %d | %d | %d | %.1f |", n, r, $3, $2, $1, a[1], a[2], $4, w }')")
  done
done
echo
echo "| scene | $key | largest energy rise at a change | largest mass restored | changes | steps | failed attempts | unknowns (most) | wall s |"
echo "|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
