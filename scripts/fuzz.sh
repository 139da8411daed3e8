#!/usr/bin/env bash
# Builds every libFuzzer target (clang, ASan+UBSan, every sanitizer finding
# fatal) and runs each for a bounded time on a copy of its seed corpus.
# Each target's whole log goes to $build_dir/fuzz-logs/<target>.log and any
# crashing, leaking or slow input to $build_dir/fuzz-crashes/<target>/; a
# failing target prints its whole log and the inputs kept. Every target
# runs; the script fails if any found something.
#   FUZZ_SECONDS=60 bash scripts/fuzz.sh
# Long offline runs: FUZZ_TARGETS="fuzz_bvh fuzz_scenario" picks targets,
# FUZZ_CORPUS_DIR=DIR keeps each target's grown corpus in DIR/<target>
# (seeded from fuzz/ on the first run, reused after) instead of a
# temporary copy, FUZZ_NICE=19 runs the targets at that niceness,
# FUZZ_JOBS=1 runs them one after another (default: one per core).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/setup.sh --deps
build_dir=${FUZZ_BUILD_DIR:-build/fuzz}
seconds=${FUZZ_SECONDS:-30}
# -O1 with line tables (the level libFuzzer's docs build with): a file
# compiles in about a fifth less time than at -O2 -g, and the sanitizers'
# reports still name file and line.
if [ ! -f "$build_dir/build.ninja" ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DTHRONG_FUZZ=ON >/dev/null
fi
cmake --build "$build_dir" -j "${JOBS:-$(nproc)}" -- --quiet
shopt -s nullglob
targets=("$build_dir"/fuzz/fuzz_*)
if [ -n "${FUZZ_TARGETS:-}" ]; then
  targets=()
  for name in $FUZZ_TARGETS; do
    [ -x "$build_dir/fuzz/$name" ] || { echo "fuzz: no target $name in $build_dir/fuzz" >&2; exit 1; }
    targets+=("$build_dir/fuzz/$name")
  done
fi
if ((${#targets[@]} == 0)); then
  echo "fuzz: no fuzz targets were built" >&2
  exit 1
fi
logs="$root/$build_dir/fuzz-logs"
crashes="$root/$build_dir/fuzz-crashes"
mkdir -p "$logs"
# run_target PATH: one target for $seconds on a copy of its seeds (or the kept
# corpus); libFuzzer's exit status goes to $logs/<target>.rc.
run_target() {
  local t=$1 name seeds work rc=0
  name=$(basename "$t")
  seeds=$(find fuzz -type d -name "corpus_${name#fuzz_}" | head -n 1)
  if [ -n "${FUZZ_CORPUS_DIR:-}" ]; then
    work="$(realpath -m "$FUZZ_CORPUS_DIR")/$name"
    if [ ! -d "$work" ]; then
      mkdir -p "$work"
      if [ -n "$seeds" ]; then cp -r "$seeds"/. "$work"/; fi
    fi
  else
    work=$(mktemp -d)
    [ -n "$seeds" ] && cp -r "$seeds"/. "$work"/
  fi
  mkdir -p "$crashes/$name"
  (cd "$work" && nice -n "${FUZZ_NICE:-0}" "$root/$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
    -artifact_prefix="$crashes/$name/" -print_final_stats=1 "$work" >"$logs/$name.log" 2>&1) || rc=$?
  [ -n "${FUZZ_CORPUS_DIR:-}" ] || rm -rf "$work"
  echo "$rc" >"$logs/$name.rc"
}
# Each target is one libFuzzer process on one core: FUZZ_JOBS of them run at
# once (default: one per core), so the run takes about
# ceil(targets / jobs) x FUZZ_SECONDS. The reports follow in target order.
jobs=${FUZZ_JOBS:-$(nproc)}
echo "fuzz: ${#targets[@]} targets for ${seconds}s each, $jobs at a time"
rm -f "$logs"/*.rc
running=0
for t in "${targets[@]}"; do
  if ((running >= jobs)); then
    wait -n
    running=$((running - 1))
  fi
  run_target "$t" &
  running=$((running + 1))
done
wait
failed=()
for t in "${targets[@]}"; do
  name=$(basename "$t")
  if [ "$(cat "$logs/$name.rc" 2>/dev/null)" = "0" ]; then
    echo "fuzz: $name ran clean"
    grep -E '^(#[0-9]+.*DONE|stat::number_of_executed_units|stat::peak_rss_mb|Done [0-9]+ runs)' "$logs/$name.log" | sed 's/^/  /' || true
  else
    echo "fuzz: $name FAILED; its whole log ($logs/$name.log):" >&2
    cat "$logs/$name.log" >&2
    echo "fuzz: inputs kept in $crashes/$name/:" >&2
    ls -l "$crashes/$name" >&2
    failed+=("$name")
  fi
  rmdir "$crashes/$name" 2>/dev/null || true  # empty: nothing found
done
if ((${#failed[@]})); then
  echo "fuzz: ${#failed[@]} target(s) failed: ${failed[*]} (inputs under $crashes)" >&2
  exit 1
fi
echo "fuzz: all ${#targets[@]} targets ran clean"
