#!/usr/bin/env bash
# The shipped 3D C. elegans scene (inputs/embryo/celegans_8.yaml, as it is
# but for t_end) to its 4-cell stage, t = 0.003 (after P1's division at
# 0.0027):
# - the three divisions by the lineage table in its order, with its names:
#   P0 -> AB, P1; AB -> ABa, ABp; P1 -> EMS, P2;
# - each first daughter's share of its mother's mass the table's fraction
#   to 1% (relative);
# - s = 0 and backward Euler at a fixed dt: each cell's mass unchanged
#   from step to step to 1e-12 relative between divisions, and the four
#   cells' masses summing to P0's;
# - the run keeps every cell: at t = 0.003 the four cells are there, named
#   ABa, ABp, EMS, P2, each with at least half its mass inside its
#   c >= 1/2 volume (a cell dissolving into its far field loses that first).
#   tests/embryo_3d.sh SOFTPACK SCENE OUTDIR
set -euo pipefail
bin=$1 scene=$2 out=$3
export OMP_NUM_THREADS=1
rm -rf "$out"
"$bin" run "$scene" --out "$out" --quiet --set time.t_end=0.003 --set output.every=1000 \
  > "$out.log" 2>&1 || { echo "FAIL: the run failed"; tail -5 "$out.log"; exit 1; }
PYTHONPATH="$(dirname "$0")" python3 - "$out" <<'EOF'
import csv, sys
out = sys.argv[1]
from checklib import check, done
want = [("P0", "AB", "P1", 0.592421), ("AB", "ABa", "ABp", 0.503495),
        ("P1", "EMS", "P2", 0.573656)]
divs = list(csv.DictReader(open(out + "/divisions.csv")))
got = [(d["parent_name"], d["first_name"], d["second_name"]) for d in divs]
check(got == [w[:3] for w in want], f"divisions {got}")
for d, w in zip(divs, want):
    share = float(d["parent_mass_after"]) / float(d["parent_mass_before"])
    check(abs(share - w[3]) <= 0.01 * w[3],
          f"{d['first_name']}: {share:.6f} of {d['parent_name']}'s mass (table {w[3]})")
rows = list(csv.DictReader(open(out + "/cells.csv")))
steps = {}
for r in rows:
    steps.setdefault(int(r["step"]), {})[r["name"]] = r
order = sorted(steps)
drift = 0.0
for s0, s1 in zip(order, order[1:]):
    if steps[s0].keys() == steps[s1].keys():
        for name, r in steps[s1].items():
            m0 = float(steps[s0][name]["mass"])
            drift = max(drift, abs(float(r["mass"]) - m0) / m0)
check(drift <= 1e-12, f"largest change of a cell's mass over a step without division {drift:.1e}")
last = steps[order[-1]]
check(float(rows[-1]["t"]) == 0.003 and sorted(last) == ["ABa", "ABp", "EMS", "P2"],
      f"at t = {rows[-1]['t']}: cells {sorted(last)}")
p0 = sum(float(r["mass"]) for r in steps[order[0]].values())
total = sum(float(r["mass"]) for r in last.values())
check(abs(total - p0) <= 1e-12 * p0, f"the four cells' masses sum to P0's: {total:.15g} / {p0:.15g}")
for name, r in sorted(last.items()):
    inside = float(r["volume"]) / float(r["mass"])
    check(inside >= 0.5, f"{name}: c >= 1/2 volume {inside:.2f} of its mass")
done()
EOF
