#!/usr/bin/env bash
# Builds (installing dependencies if needed) and runs the whole test suite.
#   bash scripts/test.sh               # Release build in build/release
#   BUILD_DIR=build/asan CMAKE_ARGS="-DTHRONG_SANITIZE=ON" BUILD_TYPE=RelWithDebInfo bash scripts/test.sh
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/setup.sh
build_dir=${BUILD_DIR:-build/release}
ctest --test-dir "$build_dir" --output-on-failure -j "${JOBS:-$(nproc)}" --timeout 900
