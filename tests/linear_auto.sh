#!/usr/bin/env bash
# solver.linear auto in 2D decides again at each layout change: mumps below
# solver.auto_unknowns unknowns, gmres_cells from there. On one cell that
# divides twice at constant volume (inputs/divide_1_2_4.yaml: 2,882, 5,764
# and 11,528 unknowns) with solver.auto_unknowns 10,000, against the same
# run with mumps throughout:
# - the run says once that it takes gmres_cells, with the unknowns of the
#   layout it takes it on (the 4-cell layout's, energy.csv's column);
# - up to that layout the two runs' energy.csv rows are byte-identical
#   (mumps in both);
# - after it as many steps, each with as many Newton iterations, and at
#   t_end the energy equal to 1e-8 relative (Newton stops at a residual
#   1e-8 of its first; GMRES's solves at 1e-4 of theirs only change its
#   path to it; the steps' times differ by what the controller makes of
#   that), the cells' masses equal to 1e-12 and every cell's mass unchanged
#   from step to step to 1e-12 relative (s = 0: GMRES on the cells' blocks
#   keeps each cell's mass at any tolerance);
# - a scene that sets the key below 0 is refused naming it, exit 2.
#   tests/linear_auto.sh SOFTPACK SCENE OUTDIR
set -euo pipefail
bin=$1 scene=$2 out=$3
export OMP_NUM_THREADS=1
rm -rf "$out"
mkdir -p "$out"
common=(--set output.pictures=false --set output.timings=false --set output.every=1000)
"$bin" run "$scene" --out "$out/mumps" "${common[@]}" --set solver.linear=mumps \
  > "$out/mumps.log" 2>&1 || { echo "FAIL: the mumps run failed"; tail -5 "$out/mumps.log"; exit 1; }
"$bin" run "$scene" --out "$out/auto" "${common[@]}" --set solver.auto_unknowns=10000 \
  > "$out/auto.log" 2>&1 || { echo "FAIL: the auto run failed"; tail -5 "$out/auto.log"; exit 1; }
fail=0
switches=$(grep -c "solver.linear auto:" "$out/auto.log" || true)
line=$(grep "solver.linear auto:" "$out/auto.log" || true)
echo "auto: $line"
[ "$switches" -eq 1 ] || { echo "FAIL: $switches solver changes, expected 1"; fail=1; }
case $line in *"gmres_cells from here ("*) ;; *) echo "FAIL: not gmres_cells"; fail=1 ;; esac
said=$(sed -n 's/.*from here (\([0-9]*\) unknowns.*/\1/p' <<< "$line")
first=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
                 $(col["unknowns"]) >= 10000 { print $(col["unknowns"]); exit }' "$out/auto/energy.csv")
echo "unknowns said: $said; first layout of energy.csv at or above 10,000: $first"
[ -n "$first" ] && [ "$said" = "$first" ] || { echo "FAIL: the unknowns differ"; fail=1; }
# rows before the first gmres_cells layout: byte-identical
n_before=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
                    $(col["unknowns"]) >= 10000 { print NR - 1; exit }' "$out/auto/energy.csv")
cmp <(head -n "$n_before" "$out/mumps/energy.csv") <(head -n "$n_before" "$out/auto/energy.csv") \
  || { echo "FAIL: the first $n_before lines of energy.csv differ"; fail=1; }
echo "energy.csv: the first $n_before lines byte-identical"
python3 - "$out/mumps" "$out/auto" <<'EOF' || fail=1
import csv, sys
a = list(csv.DictReader(open(sys.argv[1] + "/energy.csv")))
b = list(csv.DictReader(open(sys.argv[2] + "/energy.csv")))
ok = len(a) == len(b) and all(x["newton_its"] == y["newton_its"] for x, y in zip(a, b))
print(f"steps: mumps {len(a) - 1}, auto {len(b) - 1}; the same Newton iterations in each: {ok}")
ok = ok and a[-1]["t"] == b[-1]["t"]
rel = abs(float(a[-1]["energy"]) - float(b[-1]["energy"])) / abs(float(a[-1]["energy"]))
print(f"at t_end {b[-1]['t']}: relative energy difference {rel:.2e} (at most 1e-8)")
ok = ok and rel <= 1e-8
def last_masses(d):
    rows = list(csv.DictReader(open(d + "/cells.csv")))
    last = rows[-1]["step"]
    return [float(r["mass"]) for r in rows if r["step"] == last]
ma, mb = last_masses(sys.argv[1]), last_masses(sys.argv[2])
dm = max(abs(x - y) / abs(x) for x, y in zip(ma, mb)) if len(ma) == len(mb) == 4 else 1.0
print(f"the 4 cells' masses at t_end: largest relative difference {dm:.2e} (at most 1e-12)")
ok = ok and dm <= 1e-12
cells = {}
for r in csv.DictReader(open(sys.argv[2] + "/cells.csv")):
    cells.setdefault(int(r["step"]), {})[r["cell"]] = float(r["mass"])
drift = 0.0
steps = sorted(cells)
for s0, s1 in zip(steps, steps[1:]):
    if cells[s0].keys() == cells[s1].keys():  # no division between
        for k, m in cells[s1].items():
            drift = max(drift, abs(m - cells[s0][k]) / abs(cells[s0][k]))
print(f"largest relative change of a cell's mass over a step without division {drift:.2e} "
      "(at most 1e-12)")
ok = ok and drift <= 1e-12
sys.exit(0 if ok else 1)
EOF
set +e
"$bin" run "$scene" --out "$out/bad" --set solver.auto_unknowns=-1 > "$out/bad.log" 2>&1
rc=$?
set -e
grep -q "solver.auto_unknowns" "$out/bad.log" && [ $rc -eq 2 ] && [ ! -e "$out/bad" ] \
  || { echo "FAIL: solver.auto_unknowns=-1: exit $rc, not 2 naming the key with nothing written"; fail=1; }
[ $fail -eq 0 ] && echo "PASS"
exit $fail
