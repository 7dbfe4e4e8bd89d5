#!/usr/bin/env bash
# ctest deb_package (labels install, deb): cpack -G DEB builds the package,
# which is inspected and unpacked, never installed (that needs root and
# changes the machine: docs/install.md gives the commands by hand).
#   deb_package.sh BUILD_DIR CPACK VERSION SONAME_VERSION LIBDIR RUNTIME_PACKAGE...
# Checks: the control fields (name, version, Depends naming openmpi-bin and
# every runtime package CMake lists), the files under /usr (the headers
# exactly the public ones, as tests/install_tree.sh checks of the tree),
# and the unpacked bin/softpack running with the libsoftpack beside it, and
# the unpacked Python package importing with it (Depends: python3, python3-numpy).
# Exit status 77 (skipped) without dpkg-deb.
set -euo pipefail
build=$1 cpack=$2 version=$3 soversion=$4 lib=$5
shift 5
command -v dpkg-deb > /dev/null || { echo "no dpkg-deb: skipped"; exit 77; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/softpack_deb.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "deb_package: FAIL: $*" >&2; exit 1; }

"$cpack" -G DEB -B "$tmp" --config "$build/CPackConfig.cmake" > "$tmp/cpack.log" ||
  { cat "$tmp/cpack.log"; fail "cpack"; }
debs=("$tmp"/softpack_*.deb)
[ ${#debs[@]} -eq 1 ] && [ -f "${debs[0]}" ] || fail "cpack made no single softpack_*.deb"
deb=${debs[0]}
echo "built $(basename "$deb")"
dpkg-deb -I "$deb"
[ "$(dpkg-deb -f "$deb" Package)" = softpack ] || fail "package name"
[ "$(dpkg-deb -f "$deb" Version)" = "$version" ] || fail "version $(dpkg-deb -f "$deb" Version)"
depends=$(dpkg-deb -f "$deb" Depends)
for package in openmpi-bin python3 python3-numpy "$@"; do
  grep -Eq "(^|, )$package( |,|$)" <<< "$depends" || fail "Depends lacks $package: $depends"
done

dpkg-deb -c "$deb" | awk '{print $6}' > "$tmp/files"
for f in ./usr/bin/softpack "./usr/$lib/libsoftpack.so.$soversion" ./usr/include/softpack/run.h \
         "./usr/$lib/cmake/softpack/softpackConfig.cmake" "./usr/$lib/pkgconfig/softpack.pc" \
         ./usr/share/softpack/inputs/default.yaml ./usr/share/softpack/inputs/paper/embryo_8.yaml \
         ./usr/share/softpack/doc/README.md ./usr/lib/python3/dist-packages/softpack/__init__.py \
         ./usr/lib/python3/dist-packages/softpack/_install.py; do
  grep -qxF "$f" "$tmp/files" || fail "the package has no $f"
done
public="./usr/include/softpack/cell_obs.h
./usr/include/softpack/error.h
./usr/include/softpack/run.h
./usr/include/softpack/run_types.h
./usr/include/softpack/softpack_newton.h"
headers=$(grep '^\./usr/include/.*[^/]$' "$tmp/files" | LC_ALL=C sort)
[ "$headers" = "$public" ] || {
  diff <(echo "$public") <(echo "$headers") >&2 || true
  fail "the package's include/ holds other than the public headers (< expected, > packaged)"
}
echo "$(wc -l < "$tmp/files") entries, the expected files among them, the public headers only"

dpkg-deb -x "$deb" "$tmp/root"
out=$(OMP_NUM_THREADS=1 "$tmp/root/usr/bin/softpack" --version)
[[ $out == "softpack $version "* ]] || fail "the unpacked softpack --version says '$out'"
echo "unpacked: $out"
# the Python package of the unpacked tree loads the libsoftpack beside it
py=${SOFTPACK_PYTHON:-/usr/bin/python3}
if "$py" -c "import numpy" 2> /dev/null; then
  pyout=$(cd "$tmp" && env -u SOFTPACK_LIBRARY PYTHONDONTWRITEBYTECODE=1 \
    PYTHONPATH="$tmp/root/usr/lib/python3/dist-packages" "$py" -c \
    "import softpack; print(softpack.__version__, softpack.library_path())") ||
    fail "import softpack from the unpacked package: $pyout"
  [[ $pyout == "$version $tmp/root/usr/$lib/"* ]] || fail "the unpacked package's softpack: $pyout"
  echo "unpacked python: $pyout"
fi
echo "deb_package: all checks passed"
