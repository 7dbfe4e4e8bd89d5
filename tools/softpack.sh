#!/usr/bin/env bash
# softpack's two set-up commands (README.md):
#   tools/softpack.sh demo   install what is missing, build (Release), run
#                            inputs/default.yaml into out/default/ (pictures too)
#   tools/softpack.sh test   install what is missing, build, run every test (ctest)
# Everything comes from Debian's archive; nothing is downloaded otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."

# libptscotch-dev/libscotch-dev: Debian's Zoltan CMake config names their
# .so files although nothing pulls them in (docs/building.md).
PACKAGES=(cmake make g++ pkg-config
  trilinos-all-dev trilinos-dev libsuperlu-dev libsuperlu-dist-dev
  libopenmpi-dev openmpi-bin libptscotch-dev libscotch-dev libopenblas-dev
  libcyaml-dev libcairo2-dev)

install_missing() {
  local missing=() p
  for p in "${PACKAGES[@]}"; do
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
  *)
    echo "usage: tools/softpack.sh demo|test" >&2
    exit 2
    ;;
esac
