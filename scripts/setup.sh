#!/usr/bin/env bash
# Installs throng's dependencies from Debian's packages (idempotent, quiet when
# nothing is missing), then configures and builds a Release build.
#   bash scripts/setup.sh            # deps + build/release
#   bash scripts/setup.sh --deps     # deps only
#   BUILD_DIR=build/x CMAKE_ARGS="-DTHRONG_SANITIZE=ON" bash scripts/setup.sh
#   BUILD_TYPE=RelWithDebInfo BUILD_FLAGS="-O1 -g1 -DNDEBUG" bash scripts/setup.sh
#                                    # the build type's own flags replaced
#                                    # (C++, and nvcc's host code in CUDA builds)
# CMAKE_ARGS and BUILD_FLAGS take effect when $BUILD_DIR is first configured.
#   BUILD_TARGETS="throng gpu_tests" bash scripts/setup.sh   # only these targets
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

mapfile -t wanted < <(grep -v '^\s*#' scripts/packages.txt | sed '/^\s*$/d')
missing=()
for p in "${wanted[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} package(s): ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
[ "${1:-}" = "--deps" ] && exit 0

build_dir=${BUILD_DIR:-build/release}
jobs=${JOBS:-$(nproc)}
extra=()
[ "${CI:-}" = "true" ] && extra+=(-DTHRONG_WERROR=ON)
# shellcheck disable=SC2206
extra+=(${CMAKE_ARGS:-})
# One argument however many flags it holds (CMAKE_ARGS splits at spaces).
build_type=${BUILD_TYPE:-Release}
if [ -n "${BUILD_FLAGS:-}" ]; then
  extra+=("-DCMAKE_CXX_FLAGS_${build_type^^}=$BUILD_FLAGS")
  # nvcc's -O sets its host code's level (the device code keeps ptxas's own).
  [[ " ${CMAKE_ARGS:-} " == *" -DTHRONG_CUDA=ON "* ]] && extra+=("-DCMAKE_CUDA_FLAGS_${build_type^^}=$BUILD_FLAGS")
fi
if [ ! -f "$build_dir/build.ninja" ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="$build_type" "${extra[@]}" >/dev/null
fi
targets=()
for t in ${BUILD_TARGETS:-}; do targets+=(--target "$t"); done
echo "setup: building $build_dir${BUILD_TARGETS:+ (targets: $BUILD_TARGETS)}"
cmake --build "$build_dir" -j "$jobs" "${targets[@]}" -- --quiet
