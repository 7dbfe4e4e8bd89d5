# Shell functions shared by the bench scripts (sourced, not run).

# defaults_of KEY...: the program's defaults of KEY..., as "--set" and
# "KEY=VALUE" lines from `$build/softpack keys` (one word per line, for
# mapfile), so a run can take them over what a pinned scene sets.
defaults_of() {
  local k
  for k in "$@"; do
    "$build/softpack" keys | awk -F'|' -v k="\`$k\`" '{ gsub(/ /, "", $2); gsub(/ /, "", $5) }
      $2 == k { gsub(/`/, "", $2); print "--set"; print $2 "=" $5 }'
  done
}

# scene_without_cells SCENE: print SCENE without its cells list, ready for
# "cells:" and new "  - {x: ..., y: ..., radius: ...}" lines.
scene_without_cells() {
  awk '/^cells:/ { skip = 1; next } skip && /^  *-/ { next } { skip = 0; print }' "$1"
}

# packed_scene N FILE: inputs/aggregate_256.yaml (mesh, model, supports,
# solver) with N just-born cells (radius 0.065) on a hexagonal lattice of
# spacing 0.15, the N sites nearest the centre whose disks keep 0.06 from
# the ellipse, written to FILE; fails if fewer than N sites fit.
packed_scene() {
  local n=$1 file=$2 got
  scene_without_cells inputs/aggregate_256.yaml > "$file"
  echo "cells:" >> "$file"
  awk 'BEGIN { r = 0.065; h = 0.15; a = 2.0 - r - 0.06; b = 1.0 - r - 0.06
      for (j = -10; j <= 10; ++j) for (i = -20; i <= 20; ++i) {
        x = (i + (j % 2 ? 0.5 : 0)) * h; y = j * h * sqrt(3) / 2
        if ((x / a) ^ 2 + (y / b) ^ 2 <= 1) printf "%.12f %.4f %.4f\n", x * x + 4 * y * y + 1e-9 * (i + 40 * j), x, y }
    }' | sort -g | awk -v n="$n" 'NR <= n { printf "  - {x: %s, y: %s, radius: 0.065}\n", $2, $3 }' >> "$file"
  got=$(grep -c '^  - {x:' "$file")
  [ "$got" -eq "$n" ] || { echo "only $got lattice sites fit for $n cells" >&2; return 2; }
}

# packed_args [STEPS] [DT] [N ...]: the arguments of the packed-cell
# benches. Sets steps and dt (defaults 3 and 2e-5), sizes (default 16 64
# 256), t_end = steps x dt, and packed_sets, the scene overrides of such a
# run: no division or source, steps of dt to t_end, no field output.
packed_args() {
  steps=${1:-3}
  dt=${2:-2e-5}
  shift 2 || shift $#
  sizes=("$@")
  [ ${#sizes[@]} -eq 0 ] && sizes=(16 64 256)
  t_end=$(awk -v n="$steps" -v dt="$dt" 'BEGIN { printf "%.17g", n * dt }')
  packed_sets=(--set division.criterion=none --set source.rate=0 --set time.dt="$dt"
               --set time.t_end="$t_end" --set output.every=1000000)
}

# stage_pictures OUT IMG DIGITS [N ...]: copy the run OUT's energy curve and,
# for every number of cells N it passed through (or only the Ns listed),
# its last picture with N cells to IMG/cells_<N>.png, N printed DIGITS wide.
stage_pictures() {
  local out=$1 img=$2 digits=$3 png step n
  shift 3
  mkdir -p "$img"
  [ -f "$out/energy.png" ] && cp "$out/energy.png" "$img/energy.png"
  awk -F, 'NR > 1 { print $1, $5 }' "$out/energy.csv" > "$out/cells_per_step.txt"
  for png in "$out"/cells_*.png; do
    [ -e "$png" ] || continue
    step=$(basename "$png" .png | sed 's/cells_0*//'); step=${step:-0}
    n=$(awk -v s="$step" '$1 == s { print $2 }' "$out/cells_per_step.txt")
    if [ $# -eq 0 ] || [[ " $* " == *" $n "* ]]; then
      cp "$png" "$img/cells_$(printf "%0${digits}d" "$n").png" # later overwrite: the last with n cells
    fi
  done
}

# compare_runs A B: the agreement of run B with run A (two output
# directories of the same scene): energy at the steps both reached at the
# same t, cell counts there, every cell's mass and centre at each run's
# last step (the largest differences beyond 16 cells), and both lists of
# divisions.
compare_runs() {
  local a=$1 b=$2
  echo "agreement of $(basename "$b") with $(basename "$a") (energy.csv rows of the same step and t; cells at each run's last step):"
  awk -F, 'FNR == 1 { next }
    FILENAME == ARGV[1] { ea[$1] = $6; ta[$1] = $2; na[$1] = $5; next }
    ($1 in ea) { dt = $2 - ta[$1]; if (dt < 0) dt = -dt; if (dt > 1e-12 * ($2 + 1e-300)) next
                 matched++; rel = ($6 - ea[$1]) / ea[$1]; if (rel < 0) rel = -rel
                 if (rel > worst) { worst = rel; at = $1 }
                 if (na[$1] != $5) cells_differ++ }
    END { printf "  %d steps matched; largest relative energy difference %.3e (step %d); with a different cell count: %d\n",
                 matched, worst, at, cells_differ + 0 }' "$a/energy.csv" "$b/energy.csv"
  local la lb
  la=$(tail -1 "$a/cells.csv" | cut -d, -f1)
  lb=$(tail -1 "$b/cells.csv" | cut -d, -f1)
  awk -F, -v la="$la" -v lb="$lb" 'FNR == 1 { next }
    FILENAME == ARGV[1] { if ($1 == la) { m[$3] = $4; x[$3] = $5; y[$3] = $6 }; next }
    $1 == lb { dm = ($4 - m[$3]) / m[$3]; dx = $5 - x[$3]; dy = $6 - y[$3]; dc = sqrt(dx*dx + dy*dy)
      line[++n] = sprintf("  cell %d: mass rel. diff %.2e, centre moved by %.2e", $3, dm, dc)
      if (dm < 0) dm = -dm
      if (dm > wm) wm = dm; if (dc > wc) wc = dc }
    END { if (n <= 16) for (i = 1; i <= n; ++i) print line[i]
          else printf "  %d cells: mass rel. diff at most %.2e, centres moved by at most %.2e\n", n, wm, wc }' \
    "$a/cells.csv" "$b/cells.csv"
  echo "divisions ($(basename "$a"), then $(basename "$b")):"
  cut -d, -f1-5 "$a/divisions.csv" | sed 's/^/  /'
  cut -d, -f1-5 "$b/divisions.csv" | sed 's/^/  /'
}

# summary_phases LOG: from a run's closing line in LOG ("softpack: N steps
# to ..., I Newton iterations (...), S s (assembly A, factorisation F,
# solves V); ..."), "N I S A F V".
summary_phases() {
  sed -n 's/^softpack: \([0-9]*\) steps .* \([0-9]*\) Newton iterations.*, \([0-9.]*\) s (assembly \([0-9.]*\), factorisation \([0-9.]*\), solves \([0-9.]*\)).*/\1 \2 \3 \4 \5 \6/p' "$1"
}

# summary_wall RUN FILE: the wall seconds ab_runs recorded for RUN in its
# summary FILE.
summary_wall() {
  sed -n "s/^$1: $1: \([0-9.]*\) s wall.*/\1/p" "$2"
}

# ab_runs SCENE NAME_A SET_A NAME_B SET_B [--set k=v ...]: the scene run
# twice in one go, with --set SET_A (the baseline) and with --set SET_B,
# each with its wall time, peak memory, phases, Newton iterations,
# factorisations and failed attempts, then the agreement of the two runs
# (compare_runs). Honours NP (mpirun with NP processes), SOFTPACK (another
# binary) and OUT (keeps OUT/NAME_A and OUT/NAME_B).
ab_runs() {
  local scene=$1 names=("$2" "$4") sets=("$3" "$5") i run
  shift 5
  local bin=${SOFTPACK:-build/softpack} out=${OUT:-$(mktemp -d)} launch=()
  [ "${NP:-1}" -gt 1 ] && launch=(mpirun --allow-run-as-root -np "$NP")
  export OMP_NUM_THREADS=1
  local wall=()
  mkdir -p "$out"
  for i in 0 1; do
    run=${names[$i]}
    /usr/bin/time -f "$run: %e s wall, %M kB peak (rank 0)" "${launch[@]}" "$bin" run "$scene" \
        --out "$out/$run" --set "${sets[$i]}" --set output.pictures=false "$@" 2>&1 |
      grep -v "^softpack: step\|^  " | sed "s/^/$run: /" | tee "$out/$run.summary"
    wall[$i]=$(summary_wall "$run" "$out/$run.summary")
  done
  awk -v a="${wall[0]}" -v b="${wall[1]}" -v na="${names[0]}" -v nb="${names[1]}" \
    'BEGIN { if (a > 0 && b > 0) printf "wall time %s / %s: %.2f\n", na, nb, a / b }'
  echo "per accepted step (energy.csv): Newton iterations, factorisations, failed attempts, seconds"
  for run in "${names[@]}"; do
    awk -F, -v run="$run" 'NR > 1 && $1 > 0 { s++; it += $4; f += $19; fa += $20; sec += $12; fs += $14 }
      END { printf "  %s: %d steps, %.2f iterations/step, %.2f factorisations/step, %d failed attempts, %.3f s/step (factorisation %.3f)\n",
            run, s, it / s, f / s, fa, sec / s, fs / s }' "$out/$run/energy.csv"
  done
  compare_runs "$out/${names[0]}" "$out/${names[1]}"
  [ -n "${OUT:-}" ] || rm -rf "$out"
}
