#!/usr/bin/env bash
# Builds (installing dependencies if needed) and runs the whole test suite,
# then prints "tests: P passed, F failed, S skipped" and the skipped tests
# (scripts/ctest_summary.sh: under CI only GPU tests may skip).
#   bash scripts/test.sh               # Release build in build/release
#   BUILD_DIR=build/asan CMAKE_ARGS="-DTHRONG_SANITIZE=ON" BUILD_TYPE=RelWithDebInfo bash scripts/test.sh
#   CTEST_ARGS="-R Cuda" bash scripts/test.sh   # a subset
#   CTEST_EXCLUDE='^(Acceptance\.|Verify\.)' bash scripts/test.sh   # all but these (a regex)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/setup.sh
build_dir=${BUILD_DIR:-build/release}
log=$(mktemp)
trap 'rm -f "$log"' EXIT
status=0
# shellcheck disable=SC2086
ctest --test-dir "$build_dir" --output-on-failure --no-tests=error -j "${JOBS:-$(nproc)}" --timeout 900 ${CTEST_ARGS:-} \
  ${CTEST_EXCLUDE:+-E "$CTEST_EXCLUDE"} 2>&1 | tee "$log" ||
  status=$?
bash scripts/ctest_summary.sh "$log" || status=1
exit "$status"
