#!/usr/bin/env bash
# The 3D C. elegans scene at refinements 3 (docs/embryo.md, "The C. elegans 8-cell scene") with P1's cut along a fixed normal (cos B, sin B, 0), B
# degrees from the egg's axis towards ABp's side (+y: EMS, the first
# daughter, goes to the side the normal points away from, ABa's), to the
# end of the 4-cell stage (t_end 0.0041, 41 min; ABa and ABp divide at 40
# min); bench/embryo_table.py's 4-cell stage (volumes, contacts, centres,
# gaps) for each. About 70 s a run on one process.
# SEMI_Y=s: the shell's y and z semi-axes s (the scene's 0.3: 30 um; the
# coverslip's |z| <= 0.25 stays, but for s <= 0.25, not cut) with P0's y
# semi-axis scaled by s / 0.3;
# AB=A: AB's cut along the fixed normal (cos A, sin A, 0), A degrees from
# the egg's axis (90: across it, in the coverslip's plane), in place of
# the scene's perpendicular rule.
#   bench/embryo_p1_3d.sh [SOFTPACK] [OUT_DIR] [B ...]   (default B: 0 45 60 90)
set -euo pipefail
cd "$(dirname "$0")/.."
sp=${1:-build/softpack}
out=${2:-out/embryo_p1_3d}
shift 2 || shift $#
angles=("$@")
[ ${#angles[@]} -gt 0 ] || angles=(0 45 60 90)
mkdir -p "$out"
echo "bench/embryo_p1_3d.sh $sp $out ${angles[*]}; $(date -u '+%Y-%m-%d %H:%M UTC')"
semi=${SEMI_Y:-} ab=${AB:-}
# normal DEGREES: the lineage entry's fixed normal (cos, sin, 0)
normal() {
  python3 -c "import math; a = math.radians($1); \
print(f'direction_x: {math.cos(a):.6f}, direction_y: {math.sin(a):.6f}, direction_z: 0}}')"
}
tag=${semi:+s${semi}_}${ab:+ab${ab}_}
extra=()
# (a shell no taller than the coverslip's 0.25 is not cut: flatten 0)
[ -n "$semi" ] && extra+=(--set mesh.semi_y="$semi" --set mesh.semi_z="$semi"
  --set mesh.flatten="$(python3 -c "print(0.25 if $semi > 0.25 else 0)")")
ab_rule=perpendicular
[ -n "$ab" ] && ab_rule="fixed at $ab degrees"
[ -n "$semi$ab" ] && echo "shell semi_y = semi_z = ${semi:-0.3}; AB's cut: $ab_rule"
for b in "${angles[@]}"; do
  name=${tag}p1_$b
  p1=$(normal "$b")
  sed -e "/cell: P1, time/{n;s/direction_x: 1, direction_y: 0, direction_z: 0}/$p1/}" \
    inputs/embryo/celegans_8.yaml > "$out/$name.yaml"
  grep -q "$p1" "$out/$name.yaml" || { echo "P1's lineage entry not found" >&2; exit 1; }
  if [ -n "$semi" ]; then
    r0=$(python3 -c "print(f'{0.25 * $semi / 0.3:.6f}')")
    sed -i "s/{name: P0, x: 0.0, y: 0.0, z: 0.0, radius: 0.25,/{name: P0, x: 0.0, y: 0.0, z: 0.0, radius: $r0,/" "$out/$name.yaml"
    grep -q "radius: $r0," "$out/$name.yaml" || { echo "P0 not found" >&2; exit 1; }
  fi
  if [ -n "$ab" ]; then
    sed -i "/cell: AB, time/{n;s/axis: perpendicular}/axis: fixed, $(normal "$ab")/}" "$out/$name.yaml"
    grep -A1 "cell: AB, time" "$out/$name.yaml" | grep -q "axis: fixed" ||
      { echo "AB's lineage entry not found" >&2; exit 1; }
  fi
  OMP_NUM_THREADS=1 "$sp" run "$out/$name.yaml" --quiet --out "$out/$name" \
    --set mesh.refinements=3 --set model.kappa=3.2e-3 --set layout.support=local \
    --set layout.margin=12 --set solver.linear=gmres_cells --set output.pictures=true \
    --set time.t_end=0.0041 "${extra[@]}" > "$out/$name.log" 2>&1
  echo "== B = $b: P1's normal ($p1"
  bench/embryo_table.py "$out/$name" | sed -n '/^4-cell stage/,/^8-cell stage/p' | sed '$d'
done
