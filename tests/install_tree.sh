#!/usr/bin/env bash
# ctest install_tree (label install): the installed tree stands on its own.
#   install_tree.sh BUILD_DIR SOURCE_DIR CMAKE PKG_CONFIG C_COMPILER LIBDIR
# 1. cmake --install into a temporary prefix; no installed file names the
#    source or build tree (debug sections aside), the config files neither.
# 2. include/ holds the public headers and nothing else: exactly
#    softpack/{run,error,run_types,cell_obs,softpack_newton}.h (run.h and
#    what it includes; every other header of src/ and c_api/ is private).
#    Each compiles alone as <softpack/x.h>, and together they are exactly
#    what <softpack/run.h> pulls in (cc -MM).
# 3. examples/ configured with find_package(softpack) against the prefix,
#    built, run_scene run on the installed default scene for two steps: its
#    step lines and summary, and exit status 2 with the key named on a bad
#    override.
# 4. The same example compiled with pkg-config --cflags --libs softpack
#    prints the same.
# 5. The prefix moved elsewhere: bin/softpack run of the installed default
#    scene (two short steps) from a directory outside the source tree, with
#    libsoftpack found in the moved prefix.
# 6. The Python package in the moved prefix (see 6. below).
set -euo pipefail
build=$1 source=$2 cmake=$3 pkg_config=$4 cc=$5 lib=$6
tmp=$(mktemp -d "${TMPDIR:-/tmp}/softpack_install.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "install_tree: FAIL: $*" >&2; exit 1; }
export OMP_NUM_THREADS=1

prefix=$tmp/prefix
"$cmake" --install "$build" --prefix "$prefix" > "$tmp/install.log"
for f in bin/softpack $lib/cmake/softpack/softpackConfig.cmake \
         $lib/cmake/softpack/softpackConfigVersion.cmake $lib/pkgconfig/softpack.pc \
         include/softpack/run.h \
         share/softpack/inputs/default.yaml share/softpack/inputs/paper/embryo_8.yaml \
         share/softpack/doc/README.md share/softpack/doc/docs/scene.md; do
  [ -e "$prefix/$f" ] || fail "$f is not installed"
done
soname=$(objdump -p "$prefix/$lib"/libsoftpack.so | awk '$1 == "SONAME" {print $2}')
[[ $soname =~ ^libsoftpack\.so\.[0-9] ]] || fail "libsoftpack's soname is '$soname'"
[ -e "$prefix/$lib/$soname" ] || fail "no $lib/$soname"
echo "installed: $(cd "$prefix" && find . -type f | wc -l) files, soname $soname"
# Nothing installed may point into the trees it was built from.
for tree in "$(cd "$source" && pwd -P)" "$(cd "$build" && pwd -P)"; do
  while IFS= read -r -d '' f; do
    # ELF files without their debug sections (objcopy refuses other files)
    if objcopy --strip-debug "$f" "$tmp/stripped" 2> /dev/null; then
      ! grep -q -F "$tree" "$tmp/stripped" || fail "$f names $tree"
    else
      ! grep -q -F "$tree" "$f" || fail "$f names $tree"
    fi
  done < <(find "$prefix" -type f -print0)
done

# The public headers, and only they (the list of CMakeLists.txt's
# SP_PUBLIC_HEADERS, written out again on purpose: a header that turns
# public must be added to both).
public="softpack/cell_obs.h
softpack/error.h
softpack/run.h
softpack/run_types.h
softpack/softpack_newton.h"
installed=$(cd "$prefix/include" && find . -mindepth 1 ! -type d | sed 's|^\./||' | LC_ALL=C sort)
[ "$installed" = "$public" ] || {
  diff <(echo "$public") <(echo "$installed") >&2 || true
  fail "include/ holds other than the public headers (< expected, > installed)"
}
flags=$(PKG_CONFIG_PATH="$prefix/$lib/pkgconfig" "$pkg_config" --cflags --libs softpack)
libdir=$(PKG_CONFIG_PATH="$prefix/$lib/pkgconfig" "$pkg_config" --variable=libdir softpack)
cflags=$(PKG_CONFIG_PATH="$prefix/$lib/pkgconfig" "$pkg_config" --cflags softpack)
echo "pkg-config: $flags"
# Each public header compiles alone, the way a user includes it.
for h in $public; do
  echo "#include <$h>" > "$tmp/one.c"
  # shellcheck disable=SC2086 # the flags are words
  "$cc" -std=c11 -Wall -Wextra -Werror -fsyntax-only $cflags "$tmp/one.c" ||
    fail "<$h> does not compile alone against the installed tree"
done
# They are all needed: run.h's include closure is the public set.
echo "#include <softpack/run.h>" > "$tmp/run_only.c"
# shellcheck disable=SC2086
"$cc" -MM $cflags "$tmp/run_only.c" > "$tmp/run_only.d" || fail "cc -MM on <softpack/run.h>"
real_include=$(realpath "$prefix/include")
closure=$(sed 's/[\\]//g' "$tmp/run_only.d" | tr -s ' ' '\n' | grep '\.h$' |
  xargs realpath | grep -F "$real_include/" | sed "s|^$real_include/||" | LC_ALL=C sort -u)
[ "$closure" = "$public" ] ||
  fail "<softpack/run.h> includes ${closure//$'\n'/ }, not the public set ${public//$'\n'/ }"
echo "public headers (installed, each alone, run.h's closure): ${public//$'\n'/ }"

# find_package(softpack) and softpack::softpack
"$cmake" -S "$source/examples" -B "$tmp/examples" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$cc" > "$tmp/examples.log" || { cat "$tmp/examples.log"; fail "configure"; }
"$cmake" --build "$tmp/examples" > "$tmp/examples_build.log" ||
  { cat "$tmp/examples_build.log"; fail "build of examples/"; }
scene=$prefix/share/softpack/inputs/default.yaml
# run_scene: the installed default scene run through softpack/run.h with a
# step callback, two short steps (its three cells, their mass positive)
set_args=(time.dt=1e-6 time.t_end=1e-5 time.max_steps=2 output.pictures=false)
ran=$(cd "$tmp" && "$tmp/examples/run_scene" "$scene" "$tmp/run_scene_out" 0 "${set_args[@]}") ||
  fail "run_scene: $ran"
echo "$ran"
[ "$(grep -c '^step ' <<< "$ran")" -eq 2 ] &&
  grep -Eq '^step 1 t [0-9.e+-]+ dt [0-9.e+-]+ cells 3 mass [0-9]' <<< "$ran" &&
  grep -Eq '^step 2 t [0-9.e+-]+ dt [0-9.e+-]+ cells 3 mass [0-9]' <<< "$ran" &&
  grep -q "^2 steps, stopped early: no$" <<< "$ran" || fail "run_scene printed otherwise"
[ -s "$tmp/run_scene_out/energy.csv" ] || fail "run_scene wrote no energy.csv"
# the callback's centres (sp_cell_obs.centre) are cells.csv's: the
# mass-weighted centre of step 2's rows to 1e-9
want=$(awk -F, 'NR > 1 && $1 == 2 { m += $4; x += $4 * $5; y += $4 * $6 }
                END { printf "%.10g %.10g", x / m, y / m }' "$tmp/run_scene_out/cells.csv")
got=$(sed -n 's/^step 2 .* centre \([^ ]*\) \([^ ]*\)$/\1 \2/p' <<< "$ran")
awk -v w="$want" -v g="$got" 'BEGIN { split(w, a, " "); split(g, b, " ");
  exit !(b[1] != "" && (a[1] - b[1])^2 + (a[2] - b[2])^2 < 1e-18) }' ||
  fail "run_scene's centre ($got) is not cells.csv's ($want)"
# a bad override: exit status 2, the key named, nothing run
status=0
(cd "$tmp" && "$tmp/examples/run_scene" "$scene" "$tmp/bad_out" 0 time.dt=-1) \
  > "$tmp/bad.out" 2> "$tmp/bad.err" || status=$?
[ "$status" -eq 2 ] && grep -q "time.dt" "$tmp/bad.err" ||
  fail "bad override: status $status, $(cat "$tmp/bad.err")"
! grep -q '^step ' "$tmp/bad.out" || fail "a bad override ran steps"
echo "bad override: status 2, $(head -n 1 "$tmp/bad.err")"

# pkg-config --cflags --libs softpack
# shellcheck disable=SC2086 # the flags are words
"$cc" "$source/examples/run_scene.c" -o "$tmp/run_scene_pc" $flags -Wl,-rpath,"$libdir"
ran_pc=$(cd "$tmp" && "$tmp/run_scene_pc" "$scene" "$tmp/run_scene_pc_out" 0 "${set_args[@]}") ||
  fail "the pkg-config build of run_scene: $ran_pc"
[ "$ran_pc" = "$ran" ] || fail "the pkg-config build prints otherwise: $ran_pc"

# The moved tree runs a scene from outside the source tree.
mv "$prefix" "$tmp/moved"
mkdir "$tmp/work"
cd "$tmp/work"
loaded=$(ldd "$tmp/moved/bin/softpack" | awk '/libsoftpack/ {print $3}')
[ "$(realpath "$loaded")" = "$(realpath "$tmp/moved/$lib/$soname")" ] ||
  fail "the moved bin/softpack loads libsoftpack from '$loaded'"
"$tmp/moved/bin/softpack" run "$tmp/moved/share/softpack/inputs/default.yaml" \
  --set time.dt=1e-6 --set time.t_end=1e-5 --set time.max_steps=2 --set output.pictures=false
steps=$(($(wc -l < out/default/energy.csv) - 1))
[ "$steps" -ge 2 ] || fail "energy.csv has $steps rows"
[ -e out/default/fields.pvd ] || fail "no fields.pvd"
# 6. The Python package in the moved tree (docs/python.md): imported with
#    PYTHONPATH=PREFIX/lib/python3/dist-packages, it loads the moved
#    prefix's libsoftpack (whatever SOFTPACK_LIBRARY says) and runs the
#    installed default scene for two steps. Skipped without numpy.
py=${SOFTPACK_PYTHON:-/usr/bin/python3}
if "$py" -c "import numpy" 2> /dev/null; then
  pyout=$(env -u SOFTPACK_LIBRARY PYTHONDONTWRITEBYTECODE=1 \
    PYTHONPATH="$tmp/moved/lib/python3/dist-packages" "$py" -c "
import softpack, sys
print(softpack.__version__, softpack.library_path())
r = softpack.run(sys.argv[1], out='py_out', overrides={'time.dt': 1e-6, 'time.t_end': 1e-5,
                 'time.max_steps': 2, 'output.pictures': False})
print(r.steps, len(r.energy))" "$tmp/moved/share/softpack/inputs/default.yaml") ||
    fail "the installed Python package: $pyout"
  echo "python: $pyout"
  [ "$(realpath "$(sed -n '1s/^[^ ]* //p' <<< "$pyout")")" = "$(realpath "$tmp/moved/$lib/$soname")" ] ||
    fail "the installed Python package loads another libsoftpack: $pyout"
  [ "$(sed -n 2p <<< "$pyout")" = "2 3" ] || fail "the installed Python package's run: $pyout"
else
  echo "python: $py has no numpy: the Python package not checked"
fi
echo "install_tree: all checks passed"
