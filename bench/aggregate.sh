#!/usr/bin/env bash
# Scale: one cell to 256 on local supports, inputs/aggregate_256.yaml.
# Runs the scene into out/aggregate_256/ (one process, OMP_NUM_THREADS=1;
# run it with nothing else on the machine: the table is wall time) and
# prints, from its energy.csv, for every number of cells N the run passed
# through: steps, Newton iterations, unknowns (and per mesh node: the issue
# asks for a small multiple of 2), seconds per step and per step per cell,
# seconds per Newton iteration and its phases, and the per-cell cost
# against the 16-cell stage. Copies the last pictures with 16, 64, 128
# and 256 cells and the energy curve to docs/img/aggregate_256/. Under NP=2 on a
# 2-core machine the run reaches 256 cells in about 10 minutes and its t_end in
# about 23 (2.6 GB on rank 0);
# the table comes from what energy.csv holds, so a run stopped early can
# be tabled with --reuse (docs/local-support.md, "What it costs and saves").
#   bench/aggregate.sh [--reuse] [--set key=value ...]
#     (--reuse: tables and pictures of an earlier run; --set: scene overrides)
#   NP=2 bench/aggregate.sh         (under mpirun -np 2)
#   OUT=dir IMG=dir bench/aggregate.sh --reuse   (another run's outputs, pictures elsewhere)
#   SOFTPACK=path bench/aggregate.sh              (another binary, e.g. a copy)
#   SCENE=inputs/aggregate_256_defaults.yaml bench/aggregate.sh  (the scene with the defaults)
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scene=${SCENE:-inputs/aggregate_256.yaml}
out=${OUT:-out/aggregate_256}
img=${IMG:-docs/img/aggregate_256}
export OMP_NUM_THREADS=1
reuse=0
[ "${1:-}" = "--reuse" ] && { reuse=1; shift; }
if [ $reuse -eq 0 ]; then
  rm -rf "$out"
  mkdir -p out
  launch=()
  [ "${NP:-1}" -gt 1 ] && launch=(mpirun --allow-run-as-root --oversubscribe -np "$NP")
  /usr/bin/time -f "wall %e s, peak %M kB (rank 0)" "${launch[@]}" "${SOFTPACK:-build/softpack}" run "$scene" \
      --out "$out" "$@" > "$out.log" 2>&1
fi
[ -f "$out/energy.csv" ] || { echo "bench/aggregate.sh: no $out/energy.csv (run without --reuse)" >&2; exit 2; }
grep -E "^(softpack|  )|wall|peak" "$out.log" | tail -12 || true
nodes=$( (grep -o 'NumberOfPoints="[0-9]*"' "$out/fields_000000.vtu" 2>/dev/null || true) | head -1 | tr -dc 0-9)
if [ -z "$nodes" ]; then # pieces of an MPI run share nodes: count the mesh on one process
  tmp=$(mktemp -d)
  build/softpack run "$scene" --out "$tmp/o" --set time.t_end=1e-12 --set output.pictures=false > /dev/null
  nodes=$(grep -o 'NumberOfPoints="[0-9]*"' "$tmp/o/fields_000000.vtu" | head -1 | tr -dc 0-9)
  rm -rf "$tmp"
fi
echo "mesh nodes: $nodes"
echo
echo "| cells | steps | Newton its | factorisations | failed attempts | unknowns (largest) | unknowns / node | s/step | s/step/cell | s/iteration | s/iteration/cell | assembly/it | factorisation/it | solves/it | support changes | s/change | s per 1e-4 of t per cell | per cell vs 16 (step, iteration, t) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
awk -F, -v nodes="$nodes" 'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
  $1 > 0 { n = $c["n_cells"]; if (!(n in steps)) order[++k] = n
    steps[n]++; its[n] += $c["newton_its"]; sec[n] += $c["seconds"]; simt[n] += $c["dt"]
    if ("factorisations" in c) { fc[n] += $c["factorisations"]; fl[n] += $c["failed_attempts"] }
    as[n] += $c["assembly_s"]; fa[n] += $c["factorisation_s"]; so[n] += $c["solves_s"]
    ch[n] += $c["support_changed"]; sup[n] += $c["supports_s"]; if ($c["unknowns"] > u[n]) u[n] = $c["unknowns"] }
  END { if (16 in steps) { ref = sec[16] / steps[16] / 16; refit = sec[16] / its[16] / 16
                           reft = sec[16] / simt[16] / 16 }
    for (i = 1; i <= k; ++i) { n = order[i]
      per = sec[n] / steps[n] / n
      perit = sec[n] / its[n] / n
      pert = sec[n] / simt[n] / n
      printf "| %d | %d | %d | %s | %s | %d | %.2f | %.3f | %.4f | %.3f | %.4f | %.3f | %.3f | %.3f | %d | %s | %.3g | %s |\n",
        n, steps[n], its[n], ("factorisations" in c) ? fc[n] : "-", ("factorisations" in c) ? fl[n] : "-",
        u[n], u[n] / nodes, sec[n] / steps[n], per, sec[n] / its[n], perit,
        as[n] / its[n], fa[n] / its[n], so[n] / its[n], ch[n],
        ch[n] ? sprintf("%.3f", sup[n] / ch[n]) : "-", 1e-4 * pert,
        ref ? sprintf("%.2f, %.2f, %.2f", per / ref, perit / refit, pert / reft) : "-" } }' \
  "$out/energy.csv"
echo
echo "(steps with N cells include the ramp of algorithm 2 after each division: tiny steps of 2-3 iterations)"
echo
echo "The same per kind of step: the ramp of algorithm 2 (dt < 1e-5) and the others (regular):"
echo
echo "| cells | ramp steps | its/step | factorisations/step | s/step/cell | vs 16 | regular steps | its/step | factorisations/step | s/step/cell | vs 16 |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
awk -F, 'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
  $1 > 0 { n = $c["n_cells"]; if (!(n in seen)) { seen[n] = 1; order[++k] = n }
    r = $c["dt"] < 1e-5 ? 1 : 2; steps[n, r]++; its[n, r] += $c["newton_its"]; sec[n, r] += $c["seconds"]
    if ("failed_factorisations" in c) fa[n, r] += $c["factorisations"] + $c["failed_factorisations"] }
  function cell(n, r, ref) {
    if (!steps[n, r]) return "0 | - | - | - | -"
    return sprintf("%d | %.2f | %s | %.4f | %s", steps[n, r], its[n, r] / steps[n, r],
                   ("failed_factorisations" in c) ? sprintf("%.2f", fa[n, r] / steps[n, r]) : "-",
                   sec[n, r] / steps[n, r] / n, ref ? sprintf("%.2f", sec[n, r] / steps[n, r] / n / ref) : "-") }
  END { for (r = 1; r <= 2; ++r) ref[r] = steps[16, r] ? sec[16, r] / steps[16, r] / 16 : 0
    for (i = 1; i <= k; ++i) { n = order[i]; printf "| %d | %s | %s |\n", n, cell(n, 1, ref[1]), cell(n, 2, ref[2]) } }' \
  "$out/energy.csv"
echo "(factorisations/step: of the accepted attempt and the failed ones before it)"
stage_pictures "$out" "$img" 3 16 64 128 256
echo "pictures: $(ls "$img" | tr '\n' ' ')"
