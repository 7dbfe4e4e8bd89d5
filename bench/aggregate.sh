#!/usr/bin/env bash
# Scale (issue 7): one cell to 256 on local supports, inputs/aggregate_256.yaml.
# Runs the scene into out/aggregate_256/ (one process, OMP_NUM_THREADS=1;
# run it with nothing else on the machine: the table is wall time) and
# prints, from its energy.csv, for every number of cells N the run passed
# through: steps, Newton iterations, unknowns (and per mesh node: the issue
# asks for a small multiple of 2), seconds per step and per step per cell,
# seconds per Newton iteration and its phases, and the per-cell cost
# against the 16-cell stage. Copies the last pictures with 16, 64 and 256
# cells and the energy curve to docs/img/aggregate_256/. On a 24 GB machine
# the run reaches 64 cells and needs ~20 GB at 128 (docs/local-support.md):
# stop it there; the tables come from what energy.csv holds (--reuse).
#   bench/aggregate.sh [--reuse]    (--reuse: tables and pictures of an earlier run)
#   NP=2 bench/aggregate.sh         (under mpirun -np 2)
set -euo pipefail
cd "$(dirname "$0")/.."
scene=inputs/aggregate_256.yaml
out=out/aggregate_256
img=docs/img/aggregate_256
export OMP_NUM_THREADS=1
if [ "${1:-}" != "--reuse" ]; then
  rm -rf "$out"
  mkdir -p out
  launch=()
  [ "${NP:-1}" -gt 1 ] && launch=(mpirun --allow-run-as-root --oversubscribe -np "$NP")
  /usr/bin/time -f "wall %e s, peak %M kB (rank 0)" "${launch[@]}" build/softpack run "$scene" \
      --out "$out" > "$out.log" 2>&1
fi
[ -f "$out/energy.csv" ] || { echo "bench/aggregate.sh: no $out/energy.csv (run without --reuse)" >&2; exit 2; }
grep -E "^(softpack|  )|wall|peak" "$out.log" | tail -12 || true
nodes=$(grep -o 'NumberOfPoints="[0-9]*"' "$out/fields_000000.vtu" 2>/dev/null | head -1 | tr -dc 0-9)
[ -n "$nodes" ] || nodes=$(grep -ho 'NumberOfPoints="[0-9]*"' "$out"/fields_000000_p*.vtu |
                           tr -dc '0-9\n' | awk '{ s += $1 } END { print s }')
echo "mesh nodes: $nodes"
echo
echo "| cells | steps | Newton its | unknowns (largest) | unknowns / node | s/step | s/step/cell | s/iteration | assembly/it | factorisation/it | solves/it | support changes | s/change | per cell vs 16 |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
awk -F, -v nodes="$nodes" 'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
  $1 > 0 { n = $c["n_cells"]; if (!(n in steps)) order[++k] = n
    steps[n]++; its[n] += $c["newton_its"]; sec[n] += $c["seconds"]
    as[n] += $c["assembly_s"]; fa[n] += $c["factorisation_s"]; so[n] += $c["solves_s"]
    ch[n] += $c["support_changed"]; sup[n] += $c["supports_s"]; if ($c["unknowns"] > u[n]) u[n] = $c["unknowns"] }
  END { if (16 in steps) ref = sec[16] / steps[16] / 16
    for (i = 1; i <= k; ++i) { n = order[i]
      per = sec[n] / steps[n] / n
      printf "| %d | %d | %d | %d | %.2f | %.3f | %.4f | %.3f | %.3f | %.3f | %.3f | %d | %s | %s |\n",
        n, steps[n], its[n], u[n], u[n] / nodes, sec[n] / steps[n], per, sec[n] / its[n],
        as[n] / its[n], fa[n] / its[n], so[n] / its[n], ch[n],
        ch[n] ? sprintf("%.3f", sup[n] / ch[n]) : "-", ref ? sprintf("%.2f", per / ref) : "-" } }' \
  "$out/energy.csv"
echo
echo "(steps with N cells include the ramp of algorithm 2 after each division: tiny steps of 2-3 iterations)"
mkdir -p "$img"
[ -f "$out/energy.png" ] && cp "$out/energy.png" "$img/energy.png"
awk -F, 'NR > 1 { print $1, $5 }' "$out/energy.csv" > "$out/cells_per_step.txt"
for png in "$out"/cells_*.png; do
  [ -e "$png" ] || continue
  step=$(basename "$png" .png | sed 's/cells_0*//'); step=${step:-0}
  n=$(awk -v s="$step" '$1 == s { print $2 }' "$out/cells_per_step.txt")
  case "$n" in 16|64|256) cp "$png" "$img/cells_$(printf %03d "$n").png" ;; esac
done
echo "pictures: $(ls "$img" | tr '\n' ' ')"
