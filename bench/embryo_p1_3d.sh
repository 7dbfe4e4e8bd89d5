#!/usr/bin/env bash
# The 3D C. elegans scene at refinements 3 (docs/embryo.md, "3D at
# refinements 3") with P1's cut along a fixed normal (cos B, sin B, 0), B
# degrees from the egg's axis towards ABp's side (+y: EMS, the first
# daughter, goes to the side the normal points away from, ABa's), to the
# end of the 4-cell stage (t_end 0.0041, 41 min; ABa and ABp divide at 40
# min); bench/embryo_table.py's 4-cell stage (volumes, contacts, centres,
# gaps) for each. About 70 s a run on one process.
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
for b in "${angles[@]}"; do
  normal=$(python3 -c "import math; a = math.radians($b); \
print(f'direction_x: {math.cos(a):.6f}, direction_y: {math.sin(a):.6f}, direction_z: 0}}')")
  sed -e "/cell: P1, time/{n;s/direction_x: 1, direction_y: 0, direction_z: 0}/$normal/}" \
    inputs/embryo/celegans_8.yaml > "$out/p1_$b.yaml"
  grep -q "$normal" "$out/p1_$b.yaml" || { echo "P1's lineage entry not found" >&2; exit 1; }
  OMP_NUM_THREADS=1 "$sp" run "$out/p1_$b.yaml" --quiet --out "$out/p1_$b" \
    --set mesh.refinements=3 --set model.kappa=3.2e-3 --set layout.support=local \
    --set layout.margin=12 --set solver.linear=gmres_cells --set output.pictures=true \
    --set time.t_end=0.0041 > "$out/p1_$b.log" 2>&1
  echo "== B = $b: P1's normal ($normal"
  bench/embryo_table.py "$out/p1_$b" | sed -n '/^4-cell stage/,/^8-cell stage/p' | sed '$d'
done
