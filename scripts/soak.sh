#!/usr/bin/env bash
# Soak test (not in the default suite; CI runs it with THRONG_SOAK=1): the
# looping plaza at 10^3 agents for 10^6 steps and at 10^5 agents for 10^4
# steps, with `throng run --check-every 1000` failing at the first check
# that finds a non-finite agent, an agent outside free space or an overlap
# beyond the model's 8 cm bound, and at the end when resident memory grew
# more than 5% after the first tenth of the run. Prints a table of the
# figures (docs/simulation.md, "Soak test"); each run's soak.jsonl, stats.json and log are in
# $SOAK_DIR/<config>/.
#   bash scripts/soak.sh [small|large|all]        (default all)
#   SOAK_SMALL_STEPS=100000 SOAK_LARGE_STEPS=2000 bash scripts/soak.sh
# SOAK_THREADS=N passes --threads N (default: all cores), e.g. to run both
# configurations side by side.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
build_dir=${BUILD_DIR:-build/release}
throng="$build_dir/throng"
out=${SOAK_DIR:-$build_dir/soak}
every=${SOAK_CHECK_EVERY:-1000}
which=${1:-all}
case "$which" in small | large | all) ;; *)
  echo "soak: unknown configuration '$which' (small, large or all)" >&2
  exit 2
  ;;
esac
if [ ! -x "$throng" ]; then
  echo "soak: $throng is missing; build first (bash scripts/setup.sh) or set BUILD_DIR" >&2
  exit 1
fi

# name agents steps
configs=()
[ "$which" != large ] && configs+=("small ${SOAK_SMALL_AGENTS:-1000} ${SOAK_SMALL_STEPS:-1000000}")
[ "$which" != small ] && configs+=("large ${SOAK_LARGE_AGENTS:-100000} ${SOAK_LARGE_STEPS:-10000}")

failed=0
rows=()
for config in "${configs[@]}"; do
  read -r name agents steps <<<"$config"
  dir="$out/$name"
  rm -rf "$dir"
  mkdir -p "$dir"
  echo "soak: $name: plaza, $agents agents, $steps steps, checks every $every steps (log: $dir/log.txt)" >&2
  status=0
  "$throng" --threads "${SOAK_THREADS:-0}" run plaza --agents "$agents" --steps "$steps" --check-every "$every" --no-animate --no-trajectories --out "$dir" \
    >"$dir/log.txt" 2>&1 || status=$?
  if [ "$status" != 0 ]; then
    failed=1
    echo "soak: $name FAILED (exit $status):" >&2
    grep -E '^throng: error' "$dir/log.txt" >&2 || tail -5 "$dir/log.txt" >&2
  fi
  # stats.json is written only when the run reached its end; a check that
  # failed mid-run leaves soak.jsonl alone.
  rows+=("$(python3 - "$dir" "$status" <<'EOF'
import json, os, sys
d, status = sys.argv[1], sys.argv[2]
report = f"{d}/soak.jsonl"
checks = [json.loads(l) for l in open(report)] if os.path.exists(report) else []
try:
    s = json.load(open(f"{d}/stats.json"))
    soak, run, crowd = s["soak"], s["run"], s["crowd"]
    rss = soak["rss_mib"]
    print(f'{run["agents"]} | {run["steps"]} | {run["wall_seconds"]:.0f} | {100 * soak["max_overlap_m"]:.2f} | '
          f'{100 * crowd["overlaps"]["max_depth_m"]:.2f} | {rss["first"]:.1f} | {rss["after_warmup"] or 0:.1f} | {rss["end"]:.1f} | '
          f'{100 * rss["growth"]:+.1f}% | {"pass" if soak["passed"] and status == "0" else "interrupted" if soak["passed"] and status == "130" else "FAIL"}')
except (OSError, KeyError):
    last = checks[-1] if checks else {}
    print(f'? | {last.get("step", 0)} | {last.get("wall_s", 0):.0f} | {100 * last.get("max_overlap_m", 0):.2f} | - | '
          f'{checks[0]["rss_mib"] if checks else 0:.1f} | - | {last.get("rss_mib", 0):.1f} | - | FAIL')
EOF
)")
done

echo
echo "| agents | steps | wall s | deepest overlap at checks, cm | deepest overlap sampled each second, cm | RSS first, MiB | RSS after warm-up | RSS end | growth after warm-up | verdict |"
echo "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"
for r in "${rows[@]}"; do echo "| $r |"; done
exit "$failed"
