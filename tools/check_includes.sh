#!/usr/bin/env bash
# No include cycle among softpack's modules (issue 27; ctest include_cycles,
# label fast, and CI):
#   tools/check_includes.sh [SOURCE_DIR [DIR...]]    (default: . and src c_api)
# A module is one directory's x.h and x.c (or x.hpp and x.cpp) together: a
# file's `#include "y.h"` is a dependency of its module on y's module. The
# quoted name is looked up as the compiler does with -I DIR...: beside the
# including file first, then in each DIR in order; names found in none (a
# generated header) are left out, as are <...> includes. A cycle is module
# A depending on B while B depends (perhaps through others) on A, e.g.
# run_setup.c including stepper.h while stepper.c includes run_setup.h; a
# module including its own header is none.
# Exit status: 0 and one line "OK ... N modules" if there is no cycle;
# 1 with each set of modules that depend on each other (a strongly
# connected set), its shortest cycle through its first module with the
# #include lines that make it, and every include between the set's
# modules (what to cut); 2 on bad arguments. The lines are read as text: an #include inside #if 0 counts.
set -euo pipefail
root=${1:-.}
[ $# -gt 0 ] && shift
dirs=("$@")
[ ${#dirs[@]} -gt 0 ] || dirs=(src c_api)
[ -d "$root" ] || { echo "check_includes: no directory $root" >&2; exit 2; }
cd "$root"
files=()
for d in "${dirs[@]}"; do
  [ -d "$d" ] || { echo "check_includes: no directory $root/$d" >&2; exit 2; }
  for f in "$d"/*.h "$d"/*.c "$d"/*.hpp "$d"/*.cpp; do
    [ -f "$f" ] && files+=("$f")
  done
done
[ ${#files[@]} -gt 0 ] || { echo "check_includes: no source files in ${dirs[*]}" >&2; exit 2; }

# "FILE<TAB>NAME" for every #include "NAME" line, then the graph in awk.
awk '{
  if (match($0, /^[ \t]*#[ \t]*include[ \t]*"[^"]+"/)) {
    s = substr($0, RSTART, RLENGTH); sub(/^[^"]*"/, "", s); sub(/"$/, "", s)
    print FILENAME "\t" s
  }
}' "${files[@]}" | LC_ALL=C sort -u |
LC_ALL=C awk -F '\t' -v dirs="${dirs[*]}" -v list="${files[*]}" '
function module(f) { sub(/\.(h|c|hpp|cpp)$/, "", f); return f }
function dirname(f) { return sub(/\/[^\/]*$/, "", f) ? f : "." }
function resolve(from, name,   i, p) {
  p = dirname(from) "/" name
  if (p in isfile) return p
  for (i = 1; i <= ndirs; ++i) { p = dirv[i] "/" name; if (p in isfile) return p }
  return ""
}
# Tarjan: the strongly connected sets of modules (recursive; globals only,
# as awk has no local arrays)
function strong(v,   i, w, m, members) {
  idx[v] = low[v] = ++counter; stk[++sp] = v; on[v] = 1
  for (i = 1; i <= nsucc[v]; ++i) {
    w = succ[v, i]
    if (!(w in idx)) { strong(w); if (low[w] < low[v]) low[v] = low[w] }
    else if (on[w] && idx[w] < low[v]) low[v] = idx[w]
  }
  if (low[v] == idx[v]) {
    m = 0; members = ""
    do { w = stk[sp--]; on[w] = 0; comp[w] = v; ++m; members = w " " members } while (w != v)
    if (m > 1) { ++ncycles; cyc_root[ncycles] = v; cyc_size[ncycles] = m; cyc_members[ncycles] = members }
  }
}
# the shortest cycle through s inside its strongly connected set, with the
# #include lines that make each of its edges
function show(s,   head, tail, u, w, i, path, n, k, hop) {
  delete parent; head = 1; tail = 0; q[++tail] = s; parent[s] = ""
  while (head <= tail) {
    u = q[head++]
    for (i = 1; i <= nsucc[u]; ++i) {
      w = succ[u, i]
      if (comp[w] != comp[s]) continue
      if (w == s) { head = tail + 1; break }
      if (!(w in parent)) { parent[w] = u; q[++tail] = w }
    }
  }
  n = 0; for (w = u; w != ""; w = parent[w]) hop[++n] = w
  path = ""; for (k = n; k >= 1; --k) path = path hop[k] " -> "
  print "check_includes: include cycle: " path s
  for (k = n; k >= 1; --k) print "  " why[hop[k], (k > 1 ? hop[k - 1] : s)]
}
BEGIN {
  ndirs = split(dirs, dirv, " "); nfiles = split(list, filev, " ")
  for (i = 1; i <= nfiles; ++i) { isfile[filev[i]] = 1; mods[module(filev[i])] = 1 }
}
{
  to = resolve($1, $2)
  if (to == "") next
  a = module($1); b = module(to)
  if (a == b) next
  if (!((a, b) in why)) { why[a, b] = $1 " includes " $2; succ[a, ++nsucc[a]] = b; ++nedges }
  else why[a, b] = why[a, b] ", " $1 " includes " $2
}
END {
  nmods = 0
  for (m in mods) modv[++nmods] = m
  # sorted, so that the report does not depend on awk hash order
  for (i = 2; i <= nmods; ++i) { m = modv[i]; for (j = i - 1; j >= 1 && modv[j] > m; --j) modv[j + 1] = modv[j]; modv[j + 1] = m }
  for (i = 1; i <= nmods; ++i) if (!(modv[i] in idx)) strong(modv[i])
  if (ncycles == 0) {
    printf "check_includes: OK, no include cycle among %d modules (%d files, %d module dependencies) in %s\n", nmods, nfiles, nedges, dirs
    exit 0
  }
  for (c = 1; c <= ncycles; ++c) {
    # start at the set'"'"'s first module by name
    n = split(cyc_members[c], mv, " "); members = ""
    for (i = 2; i <= n; ++i) { m = mv[i]; for (j = i - 1; j >= 1 && mv[j] > m; --j) mv[j + 1] = mv[j]; mv[j + 1] = m }
    for (k = 1; k <= n; ++k) members = members " " mv[k]
    first = mv[1]
    print "check_includes: " cyc_size[c] " modules depend on each other:" members
    show(first)
    print "  all the includes between these modules:"
    for (k = 1; k <= n; ++k)
      for (i = 1; i <= nsucc[mv[k]]; ++i)
        if (comp[succ[mv[k], i]] == comp[mv[k]]) print "    " why[mv[k], succ[mv[k], i]]
  }
  printf "check_includes: FAIL, %d include cycle(s) among %d modules in %s\n", ncycles, nmods, dirs
  exit 1
}'
