#!/usr/bin/env bash
# How the 2D C. elegans scene's 4-cell stage changes with the shell's aspect
# ratio and with AB's axis rule (docs/embryo.md, "Sensitivity"): the scene
# inputs/embryo/celegans_8_2d.yaml run to t = 0.0084 (the 4-cell stage,
# before ABa and ABp divide) with
#   - the shell's semi_y in 0.25 0.30 0.35 (semi_x 0.5; P0's semi-axes
#     scaled with it, so it fills the same 76% of the section), and
#   - AB's cut: perpendicular (the scene's), long (the paper's rule), fixed
#     along x (the egg's long axis);
# printing, per run, the four cells' centres (um) and each pair's contact
# as a fraction of the smaller cell's diffuse surface (contacts.csv).
# usage: bench/embryo_sensitivity.sh [SOFTPACK] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
sp=${1:-build/softpack}
out=${2:-out/embryo_sensitivity}
mkdir -p "$out"
export OMP_NUM_THREADS=1
scene=inputs/embryo/celegans_8_2d.yaml
for semi_y in 0.25 0.30 0.35; do
  p0_y=$(python3 -c "print(round(0.26 * $semi_y / 0.3, 6))")
  for rule in perpendicular long fixed; do
    name=semi_y_${semi_y}_AB_$rule
    case $rule in
      fixed) ab="axis: fixed, direction_x: 1, direction_y: 0}" ;;
      *) ab="axis: $rule}" ;;
    esac
    sed -e "s/semi_x: 0.5, semi_y: 0.3,/semi_x: 0.5, semi_y: $semi_y,/" \
        -e "s/radius: 0.26, semi_x: 0.44}/radius: $p0_y, semi_x: 0.44}/" \
        -e "/cell: AB, time/{n;s/     axis: perpendicular}/     $ab/}" \
        "$scene" > "$out/$name.yaml"
    "$sp" run "$out/$name.yaml" --quiet --out "$out/$name" --set time.t_end=0.0084 \
      --set output.pictures=false > "$out/$name.log" 2>&1
    python3 - "$out/$name" "$name" <<'EOF'
import csv, sys
out, name = sys.argv[1], sys.argv[2]
cells = list(csv.DictReader(open(f"{out}/cells.csv")))
last = max(int(r["step"]) for r in cells)
rows = {int(r["cell"]): r for r in cells if int(r["step"]) == last}
names = {k: r["name"] for k, r in rows.items()}
con = [r for r in csv.DictReader(open(f"{out}/contacts.csv")) if int(r["step"]) == last]
surface = {int(r["cell"]): float(r["surface"]) for r in con if r["other"] == "0"}
pairs = {}
for r in con:
    k, l = int(r["cell"]), int(r["other"])
    if l:
        pairs["-".join(sorted((names[k], names[l])))] = float(r["contact"]) / min(surface[k], surface[l])
centres = ", ".join(f"{rows[k]['name']} ({50 * float(rows[k]['xc']):.1f}, {50 * float(rows[k]['yc']):.1f})"
                    for k in sorted(rows))
touch = ", ".join(f"{p} {pairs.get(p, 0):.3f}" for p in
                  ("ABa-ABp", "ABa-EMS", "ABp-EMS", "EMS-P2", "ABa-P2", "ABp-P2"))
print(f"| {name} | {centres} | {touch} |")
EOF
  done
done
