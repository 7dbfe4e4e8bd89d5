#!/usr/bin/env bash
# References that must hold (ctest check_refs, label fast, and CI):
#   tools/check_refs.sh [SOURCE_DIR]
# 1. Every path named in the docs (README.md, docs/*.md, bench/README.md)
#    and in the sources' comments (src/, c_api/, cxx_glue/, tests/, bench/,
#    tools/, examples/, cmake/, CMakeLists.txt) exists: a path is a token that
#    starts with one of the repository's folders (src/, docs/, inputs/, ...),
#    and in the docs also a markdown link's target and any NAME.md, taken
#    beside the page, in docs/ or at the top. Tokens with a placeholder
#    (an upper-case NAME, *, <, {, $) are patterns, not paths, and are left.
# 2. The user-facing text (README.md, docs/*.md, the C core's string
#    literals) names none of the Trilinos packages softpack no longer uses
#    (Epetra, AztecOO, Ifpack without the 2, ML, Amesos v1).
# 3. A section quoted as `docs/PAGE.md, "Heading"` (in docs and comments,
#    over line breaks too) is the start of one of PAGE's headings.
# docs/reports/ is left out of both: a report is the record of a study,
# written once, and may name what existed then.
# Exit status: 0 with "check_refs: OK ...", 1 with a line per dead
# reference or removed name (file:line: what), 2 on bad arguments.
set -euo pipefail
root=${1:-$(dirname "$0")/..}
[ -d "$root" ] || { echo "check_refs: no directory $root" >&2; exit 2; }
cd "$root"
bad=0 checked=0
report() { echo "check_refs: $1"; bad=$((bad + 1)); }

folders='src|c_api|cxx_glue|tests|bench|docs|tools|examples|inputs|cmake|\.ci'
# a path token: FOLDER/..., ending before a character that cannot be in one
path_re="(^|[^A-Za-z0-9_./\$}-])(($folders)/[A-Za-z0-9_./+-]*[A-Za-z0-9_/+-])"

# a pattern or a name made on purpose not to exist (a test's missing file,
# a temporary file)
is_pattern() {
  [[ "$1" =~ no_such|\.tmp$ ]] && return 0
  [[ "$1" =~ [A-Z]{2,}|\*|\<|\{|\$ ]] && [[ ! "$1" =~ ^[a-z0-9_./+-]*(README|DESIGN|MODEL|STYLE|STACK)[A-Za-z0-9_./+-]*$ ]]
}

# check_path FILE LINE PATH [BASE_DIR]
check_path() {
  local file=$1 line=$2 p=$3 base=${4:-}
  p=${p%%#*}
  p=${p%.}
  [ -n "$p" ] || return 0
  is_pattern "$p" && return 0
  checked=$((checked + 1))
  [ -e "$p" ] && return 0
  [ -n "$base" ] && [ -e "$base/$p" ] && return 0
  report "$file:$line: names $p, which does not exist"
}

docs=(README.md bench/README.md)
for f in docs/*.md; do docs+=("$f"); done
sources=()
while IFS= read -r f; do sources+=("$f"); done < <(
  find src c_api cxx_glue tests bench tools examples cmake -type f \
    \( -name '*.c' -o -name '*.h' -o -name '*.cpp' -o -name '*.hpp' -o -name '*.sh' \
       -o -name '*.py' -o -name '*.cmake' -o -name '*.txt' -o -name '*.in' \) | LC_ALL=C sort)
sources+=(CMakeLists.txt)

# 1a. folder-rooted paths, in docs and sources
for f in "${docs[@]}" "${sources[@]}"; do
  [ -f "$f" ] || continue
  [ "$f" = tools/check_refs.sh ] && continue
  while IFS=: read -r line rest; do
    while [[ "$rest" =~ $path_re ]]; do
      found=${BASH_REMATCH[2]}
      rest=${rest#*"$found"}
      after=${rest:0:1}
      # FOLDER/prefix_*.c, FOLDER/x.<ext>, ...: a pattern
      [[ "$after" =~ ^[*\<\{\$\[]$ ]] && continue
      check_path "$f" "$line" "$found"
    done
  done < <(grep -nE "$folders" "$f" || true)
done
# 1b. in the docs: markdown link targets and NAME.md, beside the page, in
#     docs/ or at the top; in the sources: NAME.md
md_re='(^|[^A-Za-z0-9_./-])([A-Za-z0-9_-]+\.md)([^A-Za-z0-9_]|$)'
link_re='\]\(([^)# ]+)'
for f in "${docs[@]}" "${sources[@]}"; do
  [ -f "$f" ] || continue
  [ "$f" = tools/check_refs.sh ] && continue
  dir=$(dirname "$f")
  is_doc=0
  [[ "$f" == *.md ]] && is_doc=1
  while IFS=: read -r line rest; do
    probe=$rest
    while [ "$is_doc" = 1 ] && [[ "$probe" =~ $link_re ]]; do
      target=${BASH_REMATCH[1]}
      probe=${probe#*"]($target"}
      [[ "$target" =~ ^(https?|mailto): ]] && continue
      check_path "$f" "$line" "$target" "$dir"
    done
    probe=$rest
    while [[ "$probe" =~ $md_re ]]; do
      name=${BASH_REMATCH[2]}
      probe=${probe#*"$name"}
      is_pattern "$name" && continue
      checked=$((checked + 1))
      [ -e "$dir/$name" ] || [ -e "docs/$name" ] || [ -e "$name" ] ||
        report "$f:$line: names $name, which is neither beside it, in docs/ nor at the top"
    done
  done < <(grep -nE '\.md|\]\(' "$f" || true)
done

# 2. removed Trilinos packages in user-facing text
removed='\b(Epetra[A-Za-z]*|AztecOO|Ifpack\b(?!2)|ML\b|Amesos( \(?v1\)?)?\b(?!2))'
for f in README.md docs/*.md; do
  { grep -nP "$removed" "$f" || true; } | while IFS=: read -r line text; do
    echo "check_refs: $f:$line: names a Trilinos package softpack does not use: $(grep -oP "$removed" <<< "$text" | head -1)"
  done
done > "${TMPDIR:-/tmp}/check_refs.$$"
# the C core's string literals (messages a user reads)
for f in $(find src -name '*.c' | LC_ALL=C sort); do
  { grep -nP "\"[^\"]*$removed[^\"]*\"" "$f" || true; } | while IFS=: read -r line text; do
    echo "check_refs: $f:$line: a message names a Trilinos package softpack does not use"
  done
done >> "${TMPDIR:-/tmp}/check_refs.$$"
if [ -s "${TMPDIR:-/tmp}/check_refs.$$" ]; then
  cat "${TMPDIR:-/tmp}/check_refs.$$"
  bad=$((bad + $(wc -l < "${TMPDIR:-/tmp}/check_refs.$$")))
fi
rm -f "${TMPDIR:-/tmp}/check_refs.$$"

# 3. quoted sections
sections=$(perl -0777 -ne '
  while (/(docs\/[a-z0-9-]+\.md),\s+"([^"]+)"/g) {
    my ($page, $heading) = ($1, $2);
    $heading =~ s/\s*(?:\n\s*(?:#|\*|\/\/)?\s*)+/ /g;   # a quote over lines of a comment
    my $line = 1 + (substr($_, 0, pos($_)) =~ tr/\n//);
    print "$ARGV:$line\t$page\t$heading\n";
  }' "${docs[@]}" "${sources[@]}" 2> /dev/null || true)
while IFS=$'\t' read -r where page heading; do
  [ -n "$where" ] || continue
  checked=$((checked + 1))
  [ -f "$page" ] || { report "$where: quotes a section of $page, which does not exist"; continue; }
  grep -E '^#+ ' "$page" | sed -E 's/^#+ +//' | grep -qF -- "$heading" ||
    report "$where: quotes the section \"$heading\" of $page, which has no such heading"
done <<< "$sections"

if [ "$bad" -gt 0 ]; then
  echo "check_refs: FAIL, $bad dead reference(s) or removed package name(s) ($checked references checked)"
  exit 1
fi
echo "check_refs: OK, $checked references checked, none dead; no removed package named"
