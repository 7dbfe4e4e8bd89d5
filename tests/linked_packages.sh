#!/usr/bin/env bash
# Trilinos 16 deprecated and 17 removes Epetra, EpetraExt, NOX's Epetra
# adapters, AztecOO, Ifpack, ML and Amesos (v1). The built
# library must not directly need (ELF DT_NEEDED, readelf -d) any of them:
# the assembly is on Tpetra, NOX runs through Thyra on Tpetra vectors
# (cxx_glue/newton.cpp), the linear solvers through their own libraries,
# Belos + Ifpack2 and Amesos2 (the successors, fine). Each one is said to
# be gone, or the test fails naming it. (Debian's own libtrilinos_tpetra
# and libtrilinos_amesos2 are built with Epetra adapters and need
# libtrilinos_epetra themselves: ldd shows it, readelf -d of softpack does
# not; docs/building.md.)
#   tests/linked_packages.sh LIBRARY
# Exit status 1 if a removed package is needed again, or if LIBRARY needs
# no Trilinos library at all (not the library this test is about).
set -uo pipefail
lib=$1
needed=$(readelf -d "$lib" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
if ! grep -q '^libtrilinos_' <<< "$needed"; then
  echo "FAIL: $lib needs no Trilinos library (readelf -d):"
  echo "$needed"
  exit 1
fi
fail=0
# package, its library (exact name: ifpack is not ifpack2, amesos not
# amesos2, epetra not epetraext)
for pkg in AztecOO:aztecoo Ifpack:ifpack ML:ml "Amesos (v1):amesos" Epetra:epetra \
           EpetraExt:epetraext NOX-Epetra:noxepetra; do
  name=${pkg%%:*} file=libtrilinos_${pkg##*:}.so
  if grep -q "^${file}\(\.\|$\)" <<< "$needed"; then
    echo "FAIL: $lib needs $file ($name is gone from softpack; Trilinos 17 removes it)"
    fail=1
  else
    echo "gone: $name ($file not directly needed)"
  fi
done
[ $fail -eq 0 ] && echo "no removed Trilinos package is linked"
exit $fail
