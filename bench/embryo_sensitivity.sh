#!/usr/bin/env bash
# How the 2D C. elegans scene's 4-cell stage changes with the shell's aspect
# ratio and with the cuts' axes (docs/embryo.md, "The C. elegans 8-cell scene"): the scene
# inputs/embryo/celegans_8_2d.yaml run to t = 0.0084 (the 4-cell stage,
# before ABa and ABp divide; about 4 s of CPU a run) with the shell's
# semi_y in 0.25 0.30 0.35 (semi_x 0.5; P0's semi-axes scaled with it, so
# it fills the same 76% of the section) and
#   rules:   AB's cut perpendicular (the scene's), long (the paper's rule),
#            fixed along x (the egg's long axis); P1's along x (the scene's);
#   diamond: AB's cut along a fixed normal (cos A, sin A), A in AB_ANGLES
#            degrees from the egg's long axis x (90 is the scene's
#            perpendicular cut, 0 the fixed x one; ABa, the first daughter,
#            on the side of -normal), and P1's along (cos B, sin B), B in
#            P1_ANGLES (0 is the scene's; EMS on the side of -normal).
#            Both rules are the lineage table's `axis: fixed`. The runs
#            are symmetric under y -> -y but for the noise, so A >= 0 and
#            B of either sign cover the cases.
# Printed per run (Markdown rows): the four cells' centres (um), each
# pair's contact as a fraction of the smaller cell's surface
# (contacts.csv; the membranes under the default output.contact_measure), and which pairs touch by the gap between their c >= 1/2
# sets (bench/embryo_table.py's, from the last fields_<step>.vtu): a pair
# touches when the gap is below GAP_UM (3 um; pressed cells read 1.1 to
# 2.9 um, a pair with a cell between them 4.8 um or more, three-cell
# corners 3.0 to 3.9 um: docs/embryo.md), and
# the arrangement that touching set makes: "diamond" (the embryo's: all
# pairs but ABa-P2; Giammona and Campas 2021, Fig 1A), "mirror" (all but
# ABp-P2), "T" (ABa-ABp, ABa-EMS, ABp-EMS, EMS-P2), "linear" (three pairs
# in a chain), otherwise the pairs themselves (the diamond table ends with
# the arrangements as a matrix per shell); a cell whose c >= 1/2 set
# is in several pieces (connected through the mesh's elements) is named
# after it ("split"), and its gaps are its largest piece's.
# usage: bench/embryo_sensitivity.sh [SOFTPACK] [OUT_DIR] [rules|diamond|all]
#   (AB_ANGLES, P1_ANGLES, SEMI_Y: space-separated lists to override;
#    SET="key=value ...": more --set overrides for every run, e.g.
#    SET=layout.support=full; REPRINT=1: print the tables from OUT_DIR's
#    runs without running them)
set -euo pipefail
cd "$(dirname "$0")/.."
sp=${1:-build/softpack}
out=${2:-out/embryo_sensitivity}
table=${3:-rules}
ab_angles=${AB_ANGLES:-15 30 45 60 75 90}
p1_angles=${P1_ANGLES:--30 0 30 45 60 75 90}
semi_ys=${SEMI_Y:-0.25 0.30 0.35}
gap_um=${GAP_UM:-3}
extra=()
for kv in ${SET:-}; do extra+=(--set "$kv"); done
mkdir -p "$out"
export OMP_NUM_THREADS=1
scene=inputs/embryo/celegans_8_2d.yaml

# fixed_axis DEGREES: the lineage entry's axis keys for the normal (cos, sin)
fixed_axis() {
  python3 -c "import math; a = math.radians($1); \
print(f'axis: fixed, direction_x: {math.cos(a):.6f}, direction_y: {math.sin(a):.6f}}}')"
}

# run_case NAME SEMI_Y AB_AXIS P1_AXIS LABEL: one run and its table row
run_case() {
  local name=$1 semi_y=$2 ab=$3 p1=$4 label=$5
  local p0_y
  p0_y=$(python3 -c "print(round(0.26 * $2 / 0.3, 6))")
  sed -e "s/semi_x: 0.5, semi_y: 0.3,/semi_x: 0.5, semi_y: $semi_y,/" \
      -e "s/radius: 0.26, semi_x: 0.44}/radius: $p0_y, semi_x: 0.44}/" \
      -e "/cell: AB, time/{n;s/     axis: perpendicular}/     $ab/}" \
      -e "/cell: P1, time/{n;s/     axis: fixed, direction_x: 1, direction_y: 0}/     $p1/}" \
      "$scene" > "$out/$name.yaml"
  [ -n "${REPRINT:-}" ] ||
    "$sp" run "$out/$name.yaml" --quiet --out "$out/$name" --set time.t_end=0.0084 \
      --set output.pictures=false "${extra[@]}" > "$out/$name.log" 2>&1
  python3 - "$out/$name" "$label" "$gap_um" <<'EOF'
import csv, math, sys
sys.path.insert(0, "bench")
from embryo_table import pieces, read_vtu_elements, read_vtu_fields
out, label, gap_um = sys.argv[1], sys.argv[2], float(sys.argv[3])
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
fields = f"{out}/fields_{last:06d}.vtu"
points, c = read_vtu_fields(fields)
elements = read_vtu_elements(fields)
parts = {names[k]: pieces(elements, {i for i, v in enumerate(c[f"c_{k}"]) if v >= 0.5})
         for k in rows}
split = [f"{n} in {len(parts[n])} pieces (the others {sum(map(len, parts[n][1:]))} nodes)"
         for n in sorted(parts) if len(parts[n]) > 1]
inside = {n: [points[i] for i in parts[n][0]] if parts[n] else [] for n in parts}
order = ("ABa-ABp", "ABa-EMS", "ABp-EMS", "EMS-P2", "ABa-P2", "ABp-P2")
gap = {}
for p in order:
    a, b = p.split("-")
    gap[p] = 50 * min(math.dist(u, v) for u in inside[a] for v in inside[b]) \
        if inside[a] and inside[b] else math.inf
touching = {p for p in order if gap[p] < gap_um}
everything = set(order)
shapes = {"diamond": everything - {"ABa-P2"}, "mirror": everything - {"ABp-P2"},
          "T": {"ABa-ABp", "ABa-EMS", "ABp-EMS", "EMS-P2"}}
shape = next((s for s, t in shapes.items() if t == touching), None)
if shape is None:
    degree = {n: sum(n in p.split("-") for p in touching) for n in ("ABa", "ABp", "EMS", "P2")}
    chain = len(touching) == 3 and sorted(degree.values()) == [1, 1, 2, 2]
    shape = "linear" if chain else ", ".join(sorted(touching))
if split:  # a cell in pieces: a far field's nucleus beside its body
    shape = f"{shape}; split: {', '.join(split)}"
centres = ", ".join(f"{rows[k]['name']} ({50 * float(rows[k]['xc']):.1f}, {50 * float(rows[k]['yc']):.1f})"
                    for k in sorted(rows))
contact = " | ".join(f"{pairs.get(p, 0):.3f}" for p in order)
gaps = " | ".join(f"{gap[p]:.1f}" for p in order)
print(f"| {label} | {centres} | {contact} | {gaps} | {shape} |")
EOF
}

header() {
  echo "| $1 | centres (x, y) um | ABa-ABp | ABa-EMS | ABp-EMS | EMS-P2 | ABa-P2 | ABp-P2" \
       "| gap ABa-ABp | ABa-EMS | ABp-EMS | EMS-P2 | ABa-P2 | ABp-P2 um | touching (gap < $gap_um um) |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
}

if [ "$table" = rules ] || [ "$table" = all ]; then
  header "shell semi_y, AB's cut"
  for semi_y in $semi_ys; do
    for rule in perpendicular long fixed; do
      case $rule in
        fixed) ab="axis: fixed, direction_x: 1, direction_y: 0}" ;;
        *) ab="axis: $rule}" ;;
      esac
      run_case "semi_y_${semi_y}_AB_$rule" "$semi_y" "$ab" \
        "axis: fixed, direction_x: 1, direction_y: 0}" "$semi_y, $rule"
    done
  done
fi
if [ "$table" = diamond ] || [ "$table" = all ]; then
  header "shell semi_y, AB's normal, P1's normal (degrees from x)"
  for semi_y in $semi_ys; do
    for a in $ab_angles; do
      for b in $p1_angles; do
        run_case "semi_y_${semi_y}_AB_${a}_P1_${b}" "$semi_y" "$(fixed_axis "$a")" \
          "$(fixed_axis "$b")" "$semi_y, $a, $b"
      done
    done
  done | tee "$out/diamond.md"
  # the same runs' arrangements as one matrix per shell
  python3 - "$out/diamond.md" <<'EOF'
import sys
from collections import defaultdict
grid = defaultdict(dict)
for line in open(sys.argv[1]):
    cols = [c.strip() for c in line.strip().strip("|").split("|")]
    semi_y, a, b = (v.strip() for v in cols[0].split(","))
    shape, _, split = cols[-1].partition("; split:")
    if shape not in ("diamond", "mirror", "T", "linear"):
        missing = [p for p in ("ABa-ABp", "ABa-EMS", "ABp-EMS", "EMS-P2", "ABa-P2", "ABp-P2")
                   if p not in shape.split(", ")]
        shape = "all but " + ", ".join(missing) if missing else "all six"
    grid[semi_y][(int(a), int(b))] = shape + (" (split)" if split else "")
for semi_y, cells in grid.items():
    ab = sorted({a for a, _ in cells})
    p1 = sorted({b for _, b in cells})
    print(f"\nshell 50 x {100 * float(semi_y):.0f} um (semi_y {semi_y}): rows AB's normal, "
          "columns P1's normal (degrees from the egg's axis x)\n")
    print("| AB \\ P1 | " + " | ".join(str(b) for b in p1) + " |")
    print("|---|" + "---|" * len(p1))
    for a in ab:
        print(f"| {a} | " + " | ".join(cells.get((a, b), "") for b in p1) + " |")
EOF
fi
