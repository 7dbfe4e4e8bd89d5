#!/usr/bin/env bash
# docs/design.md says what the code is (ctest design_doc, label fast, and CI):
#   tools/check_design.sh [SOURCE_DIR]
# 1. A fenced block right after a line `<!-- the loop: PATH -->` (or any
#    `<!-- quoted: PATH -->`) is quoted from PATH: its lines appear in PATH,
#    in order and one after another, exactly (indentation included).
# 2. Every function or type it names as sp_... exists in the sources
#    (src/, c_api/, cxx_glue/) as a whole word.
# (Its file paths: tools/check_refs.sh.)
# Exit status: 0 with "check_design: OK ...", 1 with what differs, 2 on
# bad arguments.
set -euo pipefail
root=${1:-$(dirname "$0")/..}
doc=$root/docs/design.md
[ -f "$doc" ] || { echo "check_design: no $doc" >&2; exit 2; }
cd "$root"
bad=0 quotes=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# 1. quoted blocks: awk writes each block to tmp/N with its source's path in tmp/N.path
awk -v dir="$tmp" '
  /^<!-- (the loop|quoted): [^ ]+ -->$/ { path = $0; sub(/^<!-- [^:]*: /, "", path); sub(/ -->$/, "", path); want = 1; next }
  want && /^```/ { if (inside) { inside = 0; want = 0; close(file); next } inside = 1; ++n; file = dir "/" n;
                   print path > (file ".path"); close(file ".path"); printf "" > file; next }
  inside { print >> file }
' docs/design.md
for path_file in "$tmp"/*.path; do
  [ -e "$path_file" ] || continue
  quotes=$((quotes + 1))
  block=${path_file%.path}
  src=$(cat "$path_file")
  if [ ! -f "$src" ]; then
    echo "check_design: docs/design.md quotes $src, which does not exist"; bad=$((bad + 1)); continue
  fi
  # is the block a run of consecutive lines of the source?
  if ! awk 'NR == FNR { want[++n] = $0; next }
            { line[++m] = $0 }
            END { for (s = 1; s + n - 1 <= m; ++s) { for (i = 1; i <= n && line[s + i - 1] == want[i]; ++i);
                                                       if (i > n) exit 0 }
                  exit 1 }' "$block" "$src"; then
    echo "check_design: the block quoted from $src in docs/design.md is not in it as written:"
    sed 's/^/  | /' "$block"
    bad=$((bad + 1))
  fi
done

# 2. names
names=$(grep -oE '\bsp_[a-z0-9_]+\b' docs/design.md | LC_ALL=C sort -u)
n_names=0
for name in $names; do
  n_names=$((n_names + 1))
  grep -rqw --include='*.[ch]' --include='*.[ch]pp' "$name" src c_api cxx_glue ||
    { echo "check_design: docs/design.md names $name, which is in no source"; bad=$((bad + 1)); }
done
if [ "$bad" -gt 0 ]; then
  echo "check_design: FAIL, $bad difference(s)"
  exit 1
fi
[ "$quotes" -gt 0 ] || { echo "check_design: FAIL, docs/design.md quotes no loop (<!-- the loop: PATH --> before a fenced block)"; exit 1; }
echo "check_design: OK, $quotes quoted block(s) as in their sources, $n_names sp_ names found"
