#!/usr/bin/env bash
# Trilinos 16 deprecated and 17 removes Epetra, EpetraExt, NOX's Epetra
# adapters, AztecOO, Ifpack, ML and Amesos (v1) (issue 31). The built
# library must not directly need (ELF DT_NEEDED, readelf -d) any of those
# already gone: AztecOO, Ifpack, ML, Amesos v1 (Ifpack2 and Amesos2 are
# their successors and fine). Those still used are named as such, so the
# test says what remains; one that has gone is said to be gone.
#   tests/linked_packages.sh LIBRARY
# Exit status 1 if a gone package is needed again, or if LIBRARY needs no
# Trilinos library at all (not the library this test is about).
set -uo pipefail
lib=$1
needed=$(readelf -d "$lib" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
if ! grep -q '^libtrilinos_' <<< "$needed"; then
  echo "FAIL: $lib needs no Trilinos library (readelf -d):"
  echo "$needed"
  exit 1
fi
fail=0
# gone: package, its library (exact name: ifpack is not ifpack2, amesos not amesos2)
for pkg in AztecOO:aztecoo Ifpack:ifpack ML:ml "Amesos (v1):amesos"; do
  name=${pkg%%:*} file=libtrilinos_${pkg##*:}.so
  if grep -q "^${file}\(\.\|$\)" <<< "$needed"; then
    echo "FAIL: $lib needs $file ($name is gone from softpack; Trilinos 17 removes it)"
    fail=1
  else
    echo "gone: $name ($file not directly needed)"
  fi
done
# still linked, to go (issue 31): Epetra, EpetraExt, NOX's Epetra
# adapters. Since phase 1 the assembly is on Tpetra and Epetra holds only
# NOX's vectors (cxx_glue/newton.cpp); phase 2 moves NOX to Thyra
# (NOX::Thyra::Group over a ModelEvaluator on Tpetra) and drops them.
for pkg in Epetra:epetra EpetraExt:epetraext NOX-Epetra:noxepetra; do
  name=${pkg%%:*} file=libtrilinos_${pkg##*:}.so
  if grep -q "^${file}\(\.\|$\)" <<< "$needed"; then
    echo "still linked, to go: $name ($file; only NOX's vectors in newton.cpp, until NOX runs through Thyra)"
  else
    echo "gone: $name ($file not directly needed)"
  fi
done
[ $fail -eq 0 ] && echo "no removed Trilinos package is linked"
exit $fail
