#!/usr/bin/env bash
# Reads a CTest log and prints one line: "tests: P passed, F failed, S skipped"
# (CTest's own summary counts a skipped test as passed), then the skipped
# tests by name. Fails when
#   - the log has no CTest summary, or fewer tests ran than THRONG_MIN_TESTS;
#   - with THRONG_STRICT_SKIPS=1 (CI), a test skipped that is not a GPU test.
#     GPU tests are named Cuda... (suite or test name; THRONG_ALLOWED_SKIPS,
#     an extended regex, overrides the rule): they skip on machines without
#     a GPU, which CI is. Any other skip means a check CI's environment can
#     always run did not run (e.g. ../shared missing).
#   bash scripts/ctest_summary.sh LOG
set -euo pipefail
log=$1
allowed=${THRONG_ALLOWED_SKIPS:-'(^|[./])Cuda'}
summary=$(grep -Eo '[0-9]+% tests passed, [0-9]+ tests failed out of [0-9]+' "$log" | tail -n 1 || true)
if [ -z "$summary" ]; then
  echo "tests: no CTest summary in the log: no test ran" >&2
  exit 1
fi
total=$(awk '{print $NF}' <<<"$summary")
failed=$(awk '{print $4}' <<<"$summary")
# "The following tests did not run:" lists them as "<tab>  12 - Suite.Name (Skipped)".
mapfile -t skipped < <(grep -E '^[[:space:]]+[0-9]+ - .+ \(Skipped\)$' "$log" | sed -E 's/^[[:space:]]+[0-9]+ - (.+) \(Skipped\)$/\1/' || true)
passed=$((total - failed - ${#skipped[@]}))
echo "tests: ${passed} passed, ${failed} failed, ${#skipped[@]} skipped"
status=0
for name in "${skipped[@]}"; do
  if [[ "$name" =~ $allowed ]]; then
    echo "  skipped (GPU test): $name"
  else
    echo "  skipped: $name"
    if [ "${THRONG_STRICT_SKIPS:-0}" = "1" ]; then
      echo "tests: '$name' skipped, but only GPU tests may skip here (THRONG_STRICT_SKIPS=1); its log says why" >&2
      status=1
    fi
  fi
done
min=${THRONG_MIN_TESTS:-1}
if [ "$total" -lt "$min" ]; then
  echo "tests: only ${total} tests ran, expected at least ${min} (THRONG_MIN_TESTS): tests are missing from the build" >&2
  status=1
fi
exit $status
