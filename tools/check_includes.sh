#!/usr/bin/env bash
# The include graph of softpack's sources: no include cycle between modules,
# and no include from a lower layer into a higher one (ctest include_cycles,
# label fast, and CI):
#   tools/check_includes.sh [SOURCE_DIR [DIR...]]    (default: . and src c_api cxx_glue)
# A module is one directory's x.h and x.c (or x.hpp and x.cpp) together: a
# file's `#include "y.h"` is a dependency of its module on y's module. The
# quoted name is looked up as the compiler does with -I DIR...: beside the
# including file first, then in each DIR in order; names found in none (a
# generated header) are left out, as are <...> includes. A cycle is module
# A depending on B while B depends (perhaps through others) on A; a module
# including its own header is none. The lines are read as text: an
# #include inside #if 0 counts.
#
# The layers (docs/design.md), lowest first; a file may include files of its
# own layer or lower ones only, and nothing in src/ includes cxx_glue/ (the
# core reaches the glue through c_api/ alone):
#   src/public, c_api                     0  the installed API, the glue's C door
#   src/base                              1  errors, rank agreement, faults, clocks
#   src/mesh                              2  mesh, reference element, layout, partition
#   src/scene                             3  the scene reader
#   src/model                             4  cells, division, lineage, shape, source, contacts, supports
#   src/time                              5  dt controller, time schemes
#   src/io                                6  writers, readers, pictures, initial state
#   src/run                               7  the run: loop, step, events, monitor, checkpoints, main
#   src/python                            8  the Python package (no C)
#   cxx_glue/base 3, cxx_glue/linear 4, cxx_glue/assembly 5, cxx_glue (top) 6
# Exit status: 0 and one line "OK ..." if there is no cycle and no upward
# include; 1 with each set of modules that depend on each other (a strongly
# connected set), its shortest cycle through its first module with the
# #include lines that make it, every include between the set's modules
# (what to cut), and each upward include; 2 on bad arguments.
set -euo pipefail
root=${1:-.}
[ $# -gt 0 ] && shift
dirs=("$@")
[ ${#dirs[@]} -gt 0 ] || dirs=(src c_api cxx_glue)
[ -d "$root" ] || { echo "check_includes: no directory $root" >&2; exit 2; }
cd "$root"
files=()
for d in "${dirs[@]}"; do
  [ -d "$d" ] || { echo "check_includes: no directory $root/$d" >&2; exit 2; }
  while IFS= read -r f; do files+=("$f"); done < <(find "$d" -type f \( -name '*.h' -o -name '*.c' \
    -o -name '*.hpp' -o -name '*.cpp' \) | LC_ALL=C sort)
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
function layer(f) {
  if (f ~ /^src\/public\// || f ~ /^c_api\//) return 0
  if (f ~ /^src\/base\//) return 1
  if (f ~ /^src\/mesh\//) return 2
  if (f ~ /^src\/scene\//) return 3
  if (f ~ /^src\/model\//) return 4
  if (f ~ /^src\/time\//) return 5
  if (f ~ /^src\/io\//) return 6
  if (f ~ /^src\/run\//) return 7
  if (f ~ /^src\/python\//) return 8
  if (f ~ /^cxx_glue\/base\//) return 3
  if (f ~ /^cxx_glue\/linear\//) return 4
  if (f ~ /^cxx_glue\/assembly\//) return 5
  if (f ~ /^cxx_glue\//) return 6
  return -1
}
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
  if (layer($1) < 0 || layer(to) < 0) { unplaced[$1] = 1 }
  else if (layer(to) > layer($1) || ($1 ~ /^src\// && to ~ /^cxx_glue\//)) {
    upward[++nup] = $1 " (layer " layer($1) ") includes " $2 " (" to ", layer " layer(to) ")"
  }
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
  for (i = 1; i <= nup; ++i) print "check_includes: upward include: " upward[i]
  for (f in unplaced) print "check_includes: " f " is in no layer (add its folder to tools/check_includes.sh)"
  bad = nup > 0 || length(unplaced) > 0
  if (ncycles == 0 && !bad) {
    printf "check_includes: OK, no include cycle and no upward include among %d modules (%d files, %d module dependencies) in %s\n", nmods, nfiles, nedges, dirs
    exit 0
  }
  if (ncycles == 0) {
    printf "check_includes: FAIL, %d upward include(s)\n", nup
    exit 1
  }
  if (0) {
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
