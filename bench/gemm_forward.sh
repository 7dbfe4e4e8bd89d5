#!/usr/bin/env bash
# The BLAS's one-column products (cxx_glue/base/blas_forward.cpp): the same
# fixed steps with DGEMM(N = 1) handed to DGEMV (the default) and with
# SOFTPACK_GEMM_FORWARD=0 (every call to the BLAS's DGEMM), alternated
# ROUNDS times so that the machine's drift falls on both alike; prints
# each run's seconds (total, factorisation, solves) and the medians' ratios.
#   bench/gemm_forward.sh [CASE ...]
#   CASE: relax256 (inputs/bench/relax_3.yaml on 256^2 elements: 3 cells,
#         396,294 unknowns, gmres_cells), default6 (inputs/default.yaml at
#         refinements 6, MUMPS), 3d3 (the 3D run 5's ellipsoid at
#         refinements 3, gmres_cells); default: all three.
#   ROUNDS (default 3), STEPS (default 4), NP (default 1).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
build=${BUILD:-build}
rounds=${ROUNDS:-3}
steps=${STEPS:-4}
np=${NP:-1}
cases=("$@")
[ ${#cases[@]} -eq 0 ] && cases=(relax256 default6 3d3)
export OMP_NUM_THREADS=1
launch=()
[ "$np" -gt 1 ] && launch=(mpirun --allow-run-as-root --oversubscribe -np "$np")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

scene_of() { # CASE: the scene and its overrides
  case $1 in
    relax256) echo inputs/bench/relax_3.yaml --set mesh.nx=256 --set mesh.ny=256 ;;
    default6) echo inputs/default.yaml --set mesh.refinements=6 ;;
    3d3) echo inputs/3d/embryo_8.yaml --set mesh.refinements=3 ;;
    *) echo "bench/gemm_forward.sh: unknown case '$1'" >&2; exit 2 ;;
  esac
}

echo "bench/gemm_forward.sh ${cases[*]} (ROUNDS=$rounds STEPS=$steps NP=$np), $(date -u +%F), $(uname -m), $(getconf _NPROCESSORS_ONLN) cores"
printf '%-9s %-8s %5s %10s %10s %10s\n' case forward round seconds factor solves
for c in "${cases[@]}"; do
  read -r -a scene <<< "$(scene_of "$c")"
  for ((r = 1; r <= rounds; ++r)); do
    for fwd in 1 0; do
      out=$tmp/$c.$fwd.$r
      SOFTPACK_GEMM_FORWARD=$fwd "${launch[@]}" "$build/softpack" run "${scene[@]}" --out "$out" \
        --set time.max_steps="$steps" --set output.pictures=false --set output.every=1000000 \
        > "$out.log" 2>&1 || { echo "$c forward=$fwd failed:"; tail -3 "$out.log"; exit 1; }
      read -r _ _ s _ f v < <(summary_phases "$out.log")
      printf '%-9s %-8s %5d %10s %10s %10s\n' "$c" "$fwd" "$r" "$s" "$f" "$v"
      echo "$s $f $v" >> "$tmp/$c.$fwd.all"
    done
  done
  # the same arithmetic up to the kernels' order of summation: the energies
  cut -d, -f1-6 "$tmp/$c.1.1/energy.csv" > "$tmp/a" && cut -d, -f1-6 "$tmp/$c.0.1/energy.csv" > "$tmp/b"
  paste -d, "$tmp/a" "$tmp/b" | awk -F, 'NR > 2 { d = ($6 - $12) / $12; if (d < 0) d = -d; if (d > w) w = d }
      END { printf "  energies of the two differ by at most %.1e relative\n", w }'
  median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
  for col in 1 2 3; do
    on=$(awk -v c=$col '{ print $c }' "$tmp/$c.1.all" | median)
    off=$(awk -v c=$col '{ print $c }' "$tmp/$c.0.all" | median)
    awk -v n="$(echo total factorisation solves | cut -d' ' -f$col)" -v a="$on" -v b="$off" \
      'BEGIN { printf "  median %s: %.1f s through DGEMV, %.1f s through DGEMM: %.2fx\n", n, a, b, b / a }'
  done
done
