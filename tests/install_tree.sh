#!/usr/bin/env bash
# ctest install_tree (label install): the installed tree stands on its own.
#   install_tree.sh BUILD_DIR SOURCE_DIR CMAKE PKG_CONFIG C_COMPILER LIBDIR
# 1. cmake --install into a temporary prefix; no installed file names the
#    source or build tree (debug sections aside), the config files neither.
# 2. examples/ configured with find_package(softpack) against the prefix,
#    built, run on the installed default scene: its facts, and exit status 2
#    with the library's message on a bad override.
# 3. The same example compiled with pkg-config --cflags --libs softpack
#    prints the same.
# 4. The prefix moved elsewhere: bin/softpack run of the installed default
#    scene (two short steps) from a directory outside the source tree, with
#    libsoftpack found in the moved prefix.
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
         include/softpack/scene.h include/softpack/softpack_solver.h \
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

# find_package(softpack) and softpack::softpack
"$cmake" -S "$source/examples" -B "$tmp/examples" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$cc" > "$tmp/examples.log" || { cat "$tmp/examples.log"; fail "configure"; }
"$cmake" --build "$tmp/examples" > "$tmp/examples_build.log" ||
  { cat "$tmp/examples_build.log"; fail "build of examples/"; }
scene=$prefix/share/softpack/inputs/default.yaml
facts=$("$tmp/examples/scene_facts" "$scene")
echo "$facts"
grep -q "^mesh: ellipse, 5376 elements, 5441 nodes" <<< "$facts" || fail "mesh facts"
grep -q "^cells: 3$" <<< "$facts" || fail "cell count"
grep -q "^  cell 1 at (-0.2, 0), radius 0.13$" <<< "$facts" || fail "first cell"
status=0
"$tmp/examples/scene_facts" "$scene" time.dt=-1 2> "$tmp/bad.err" || status=$?
[ "$status" -eq 2 ] && grep -q "time.dt" "$tmp/bad.err" ||
  fail "bad override: status $status, $(cat "$tmp/bad.err")"

# run_scene: a scene run through softpack/run.h with a step callback
ran=$(cd "$tmp" && "$tmp/examples/run_scene" "$scene" "$tmp/run_scene_out" 0 time.dt=1e-6 \
  time.t_end=1e-5 time.max_steps=2 output.pictures=false) ||
  fail "run_scene: $ran"
echo "$ran"
grep -q "^step 2 t " <<< "$ran" && grep -q "^2 steps, stopped early: no$" <<< "$ran" ||
  fail "run_scene printed otherwise"

# pkg-config --cflags --libs softpack
flags=$(PKG_CONFIG_PATH="$prefix/$lib/pkgconfig" "$pkg_config" --cflags --libs softpack)
libdir=$(PKG_CONFIG_PATH="$prefix/$lib/pkgconfig" "$pkg_config" --variable=libdir softpack)
echo "pkg-config: $flags"
# shellcheck disable=SC2086 # the flags are words
"$cc" "$source/examples/scene_facts.c" -o "$tmp/scene_facts_pc" $flags -Wl,-rpath,"$libdir"
[ "$("$tmp/scene_facts_pc" "$scene")" = "$facts" ] || fail "the pkg-config build prints otherwise"

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
echo "install_tree: all checks passed"
