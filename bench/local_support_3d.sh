#!/usr/bin/env bash
# Full against local supports on the 3D run 5 (inputs/3d/embryo_8.yaml):
# the same run with each layout (bench/lib.sh ab_runs: wall
# time, peak memory, the largest unknown count, per-step iterations and
# factorisations, the runs' agreement), then per number of cells the
# steps, the simulated time they cover, wall seconds per step (and its
# assembly, factorisation, solves, support changes) and per 0.001 of
# simulated time, unknowns per step and per cell.
#   bench/local_support_3d.sh [REFINEMENTS] [--set k=v ...]
# REFINEMENTS: mesh.refinements (default 3: 4589 nodes with the buffer).
# Without --set the runs go to the scene's t_end (1 -> 8 cells); e.g.
# --set time.max_steps=20 stops both after 20 steps. NP=2 runs each on
# two processes; SOFTPACK=path runs another binary; OUT=dir keeps both
# runs (dir/full, dir/local; otherwise a temporary directory, removed at
# the end).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scene=inputs/3d/embryo_8.yaml
refinements=${1:-3}
shift || true
out=${OUT:-$(mktemp -d)}
echo "$scene, mesh.refinements=$refinements $*; $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc --all) cores"
OUT=$out ab_runs "$scene" full layout.support=full local layout.support=local \
  --set mesh.refinements="$refinements" "$@"
echo
echo "| supports | cells | steps | t covered | s/step | assembly | factorisation | solves | supports | s per 0.001 of t | unknowns/step | unknowns/cell | support changes |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for mode in full local; do
  awk -F, -v mode="$mode" 'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
    $1 > 0 { n = $c["n_cells"]; if (!(n in k)) order[++m] = n
             k[n]++; dt[n] += $c["dt"]; sec[n] += $c["seconds"]; as[n] += $c["assembly_s"]
             fa[n] += $c["factorisation_s"]; so[n] += $c["solves_s"]; su[n] += $c["supports_s"]
             u[n] += $c["unknowns"]; ch[n] += $c["support_changed"] }
    END { for (i = 1; i <= m; ++i) { n = order[i]
            printf "| %s | %d | %d | %.3g | %.3f | %.3f | %.3f | %.3f | %.3f | %.1f | %.0f | %.0f | %d |\n",
                   mode, n, k[n], dt[n], sec[n] / k[n], as[n] / k[n], fa[n] / k[n], so[n] / k[n],
                   su[n] / k[n], 1e-3 * sec[n] / dt[n], u[n] / k[n], u[n] / k[n] / n, ch[n] } }' \
    "$out/$mode/energy.csv"
done
[ -n "${OUT:-}" ] || rm -rf "$out"
