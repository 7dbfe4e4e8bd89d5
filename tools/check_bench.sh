#!/usr/bin/env bash
# The benchmark suite runs on today's options (ctest bench_scripts, label
# fast, and CI): a dry check of every script of bench/, without running it.
#   tools/check_bench.sh SOFTPACK [SOURCE_DIR]
# For each bench/*.sh and bench/*.py: it parses (bash -n; python3's
# compile for .py); every scene key it sets (section.key=...) is one of
# `SOFTPACK keys`; every scene or file of the repository it names exists
# (tools/check_refs.sh checks that for all the sources); and bench/README.md
# lists it. Every bench_*.c program is listed there too.
# Exit status: 0 with "check_bench: OK ...", 1 with what is wrong, 2 on
# bad arguments.
set -euo pipefail
softpack=${1:?usage: tools/check_bench.sh SOFTPACK [SOURCE_DIR]}
root=${2:-$(dirname "$0")/..}
[ -x "$softpack" ] || { echo "check_bench: $softpack is not a program" >&2; exit 2; }
cd "$root"
keys=$("$softpack" keys | sed -n 's/^| `\([a-z_0-9]*\.[a-z_0-9]*\)` |.*/\1/p')
[ -n "$keys" ] || { echo "check_bench: '$softpack keys' listed no key" >&2; exit 2; }
sections=$(sed 's/\..*//' <<< "$keys" | LC_ALL=C sort -u | paste -sd'|')
bad=0 n=0
for f in bench/*.sh bench/*.py bench/bench_*.c; do
  [ -f "$f" ] || continue
  name=$(basename "$f")
  [ "$name" = lib.sh ] && continue
  n=$((n + 1))
  grep -q "\b${name}\b" bench/README.md ||
    { echo "check_bench: bench/README.md does not list $name"; bad=$((bad + 1)); }
  case $f in
    *.sh) bash -n "$f" || { echo "check_bench: $f does not parse"; bad=$((bad + 1)); } ;;
    *.py) python3 -c "import ast, sys; ast.parse(open(sys.argv[1]).read())" "$f" ||
            { echo "check_bench: $f does not parse"; bad=$((bad + 1)); } ;;
    *) continue ;;
  esac
  for key in $(grep -v '^\s*#' "$f" | grep -oE "\b($sections)\.[a-z_0-9]+=" | tr -d = | LC_ALL=C sort -u); do
    grep -qx "$key" <<< "$keys" ||
      { echo "check_bench: $f sets $key, which softpack does not know"; bad=$((bad + 1)); }
  done
done
[ "$bad" -eq 0 ] || { echo "check_bench: FAIL, $bad problem(s) in $n bench scripts and programs"; exit 1; }
echo "check_bench: OK, $n bench scripts and programs: they parse, set known keys, and bench/README.md lists them"
