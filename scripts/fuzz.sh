#!/usr/bin/env bash
# Builds every libFuzzer target (clang, ASan+UBSan) and runs each for a
# bounded time on a copy of its seed corpus. Fails on the first crash.
#   FUZZ_SECONDS=60 bash scripts/fuzz.sh
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/setup.sh --deps
build_dir=${FUZZ_BUILD_DIR:-build/fuzz}
seconds=${FUZZ_SECONDS:-30}
if [ ! -f "$build_dir/build.ninja" ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DTHRONG_FUZZ=ON >/dev/null
fi
cmake --build "$build_dir" -j "${JOBS:-$(nproc)}" -- --quiet
shopt -s nullglob
targets=("$build_dir"/fuzz/fuzz_*)
if ((${#targets[@]} == 0)); then
  echo "fuzz: no fuzz targets"
  exit 0
fi
for t in "${targets[@]}"; do
  name=$(basename "$t")
  seeds=$(find fuzz -type d -name "corpus_${name#fuzz_}" | head -n 1)
  work=$(mktemp -d)
  [ -n "$seeds" ] && cp -r "$seeds"/. "$work"/
  echo "fuzz: $name for ${seconds}s (seeds: ${seeds:-none})"
  (cd "$work" && "$root/$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
     -print_final_stats=1 "$work" 2>&1 | tail -n 12)
  rm -rf "$work"
done
echo "fuzz: all targets ran clean"
