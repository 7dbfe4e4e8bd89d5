# Shell functions shared by the bench scripts (sourced, not run).

# scene_without_cells SCENE: print SCENE without its cells list, ready for
# "cells:" and new "  - {x: ..., y: ..., radius: ...}" lines.
scene_without_cells() {
  awk '/^cells:/ { skip = 1; next } skip && /^  *-/ { next } { skip = 0; print }' "$1"
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
