#!/usr/bin/env bash
# The cognitive complexity of every function in src/'s C files (clang-tidy's
# readability-function-cognitive-complexity), highest first, against the
# limits of docs/design.md: no function of the run's modules (src/run/'s
# loop, step, events, monitor, set-up, resize, options, and the cell
# registry) above RUN_LIMIT (40), none in src/ above SRC_LIMIT (60).
#
#   tools/complexity.sh [SOURCE_DIR] [TOP]   (tools/softpack.sh complexity)
#
# Prints the TOP (default 15) most complex functions and exits 1 if a
# limit is exceeded. Needs clang-tidy and the build's headers (Debian:
# clang-tidy, libopenmpi-dev, libhdf5-openmpi-dev, libcairo2-dev, libnifti2-dev).
set -uo pipefail
src=${1:-$(dirname "$0")/..}
top=${2:-15}
RUN_LIMIT=40 SRC_LIMIT=60
RUN_MODULES="stepper step events monitor run_setup resize run_options registry"
flags=(-std=c11 -D_POSIX_C_SOURCE=200809L -I"$src/src" -I"$src/c_api"
       $(mpicc --showme:compile 2> /dev/null)
       $(pkg-config --cflags hdf5-openmpi cairo 2> /dev/null) -I/usr/include/nifti)
# sp_revision.h is generated at build time: a stand-in
gen=$(mktemp -d)
trap 'rm -rf "$gen"' EXIT
echo '#define SP_GIT_REVISION "unknown"' > "$gen/sp_revision.h"
flags+=(-I"$gen")
table=$gen/table
for f in "$src"/src/*/*.c; do
  clang-tidy --quiet -checks='-*,readability-function-cognitive-complexity' \
    -config="{CheckOptions: [{key: readability-function-cognitive-complexity.Threshold, value: 0}]}" \
    "$f" -- "${flags[@]}" 2> /dev/null |
    sed -n "s|^.*/src/[a-z]*/\([a-z_0-9]*\)\.c:\([0-9]*\):[0-9]*: warning: function '\([^']*\)' has cognitive complexity of \([0-9]*\).*|\4 \1 \3 \2|p"
done | sort -k1,1nr > "$table"
[ -s "$table" ] || { echo "complexity: clang-tidy reported nothing (missing headers?)" >&2; exit 1; }
printf '%-6s %-14s %s\n' complexity module function
head -n "$top" "$table" | awk '{ printf "%-6s %-14s %s (line %s)\n", $1, $2 ".c", $3, $4 }'
status=0
while read -r c module fn line; do
  limit=$SRC_LIMIT
  [[ " $RUN_MODULES " == *" $module "* ]] && limit=$RUN_LIMIT
  if [ "$c" -gt "$limit" ]; then
    echo "complexity: $module.c: $fn has $c, above the limit $limit" >&2
    status=1
  fi
done < "$table"
echo "complexity: $(wc -l < "$table") functions; largest in the run's modules:" \
  "$(awk -v m=" $RUN_MODULES " 'index(m, " " $2 " ") { print $1 " (" $2 ".c " $3 ")"; exit }' "$table")"
exit $status
