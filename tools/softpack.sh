#!/usr/bin/env bash
# softpack's two set-up commands (README.md):
#   tools/softpack.sh demo   install what is missing, build (Release), run
#                            inputs/default.yaml into out/default/ (pictures too)
#   tools/softpack.sh test   install what is missing, build, run every test (ctest)
#   tools/softpack.sh valgrind   memcheck on a bad-input run and a short real run
#   tools/softpack.sh sanitize   build-sanitize/ with -fsanitize=address,undefined,
#                                run the fast tests (ctest -L fast)
#   tools/softpack.sh fuzz [SECONDS]   libFuzzer on the scene reader (default 600 s)
#   (these three: docs/robustness.md)
#   tools/softpack.sh complexity   clang-tidy's cognitive complexity of src/'s
#                                  functions, against the limits of docs/design.md
# Everything comes from Debian's archive; nothing is downloaded otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."

# libptscotch-dev/libscotch-dev: Debian's Zoltan CMake config names their
# .so files although nothing pulls them in (docs/building.md).
# python3-*: the Python package (src/python/softpack, docs/python.md) needs
# numpy only; pytest runs its tests (ctest -L python); pandas, yaml, mpi4py,
# matplotlib, nibabel are used where present (and by its tests and
# examples/); nbformat/nbconvert/ipykernel execute the example notebook.
PACKAGES=(cmake make g++ pkg-config
  trilinos-all-dev trilinos-dev libsuperlu-dev libsuperlu-dist-dev libmumps-dev libsuitesparse-dev
  libopenmpi-dev openmpi-bin libptscotch-dev libscotch-dev libopenblas-dev
  libcyaml-dev libcairo2-dev libhdf5-openmpi-dev libnifti2-dev
  python3-numpy python3-pytest python3-pandas python3-yaml python3-mpi4py python3-matplotlib
  python3-nibabel python3-nbformat python3-nbconvert python3-ipykernel)

# install_missing [EXTRA_PACKAGE...]: PACKAGES and the extras a command needs
install_missing() {
  local missing=() p
  for p in "${PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "softpack: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
}

build() {
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
  cmake --build build -j 2
}

# run_memcheck EXPECTED_STATUS COMMAND...: COMMAND under valgrind's memcheck;
# any invalid or uninitialised read, or a definite leak not suppressed by
# tools/valgrind.supp (libraries' own), makes valgrind exit 99.
run_memcheck() {
  local expected=$1 status=0
  shift
  echo "softpack: valgrind $*"
  nice -n 19 valgrind --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite \
    --show-leak-kinds=definite --num-callers=60 --suppressions=tools/valgrind.supp \
    "$@" || status=$?
  if [ "$status" -ne "$expected" ]; then
    echo "softpack: valgrind: exit status $status, expected $expected (99: memcheck errors)" >&2
    exit 1
  fi
}

# Debian's SuperLU_DIST and OpenBLAS start threads; one per process is
# fastest on small machines and required under MPI.
export OMP_NUM_THREADS=1

case "${1:-}" in
  demo)
    install_missing
    build
    build/softpack run inputs/default.yaml --out out/default
    echo "softpack: pictures and fields in out/default/ (open fields.pvd in ParaView)"
    ;;
  test)
    install_missing
    build
    cd build && ctest --output-on-failure -j 2
    ;;
  complexity)
    install_missing clang-tidy
    exec tools/complexity.sh . "${2:-15}"
    ;;
  valgrind)
    install_missing valgrind
    build
    tmp=$(mktemp -d)
    trap 'rm -rf "$tmp"' EXIT
    # bad input: exit 2, nothing written, nothing read uninitialised
    run_memcheck 2 build/softpack run tests/scenes/two_overlapping.yaml \
      --set time.dt=-1 --out "$tmp/bad"
    [ ! -e "$tmp/bad" ] || { echo "softpack: valgrind: bad input wrote $tmp/bad" >&2; exit 1; }
    # two steps of two cells with local supports (and energy.png)
    run_memcheck 0 build/softpack run tests/scenes/local_short.yaml \
      --set time.max_steps=2 --set mesh.nx=40 --set mesh.ny=24 --out "$tmp/run"
    echo "softpack: valgrind: both runs clean"
    ;;
  sanitize)
    install_missing
    cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSOFTPACK_SANITIZE=ON
    cmake --build build-sanitize -j 2 --target fast_tests
    # any report ends the process with a failure: UB aborts, leaks fail the
    # exit (only those inside the libraries of tools/lsan.supp are forgiven);
    # the slow unwinder records whole allocation stacks, so that a leak made
    # in an Open MPI component (dlclose'd before the leak check) still shows
    # the libmpi frames below it
    export ASAN_OPTIONS=abort_on_error=1:detect_leaks=1:strict_string_checks=1
    ASAN_OPTIONS+=:fast_unwind_on_malloc=0
    export UBSAN_OPTIONS=halt_on_error=1:abort_on_error=1:print_stacktrace=1
    export LSAN_OPTIONS=suppressions=$PWD/tools/lsan.supp:print_suppressions=0
    cd build-sanitize && ctest -L fast --output-on-failure
    ;;
  fuzz)
    seconds=${2:-600}
    install_missing clang libclang-rt-14-dev
    CC=clang CXX=clang++ cmake -S . -B build-fuzz -DSOFTPACK_FUZZ=ON \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo
    cmake --build build-fuzz -j 2
    # seeds: every scene of the repository, the broken ones and the kept
    # fuzz findings included; the corpus grows in build-fuzz/corpus
    rm -rf build-fuzz/seeds
    mkdir -p build-fuzz/seeds build-fuzz/corpus build-fuzz/crashes
    find inputs tests/scenes -type f -name '*.yaml' | while read -r f; do
      cp "$f" "build-fuzz/seeds/$(echo "$f" | tr / _)"
    done
    # one process; a finding stops the run and is written to build-fuzz/crashes/
    # (keep it under tests/scenes/fuzz/, where test_fuzz_regressions loads it)
    nice -n 19 build-fuzz/fuzz_scene -max_total_time="$seconds" -timeout=10 \
      -rss_limit_mb=2048 -print_final_stats=1 -dict=tests/fuzz/scene.dict \
      -artifact_prefix=build-fuzz/crashes/ build-fuzz/corpus build-fuzz/seeds
    ;;
  *)
    echo "usage: tools/softpack.sh demo|test|valgrind|sanitize|fuzz [SECONDS]" >&2
    exit 2
    ;;
esac
