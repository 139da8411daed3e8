#!/usr/bin/env bash
# The size limits of src/ (docs/architecture.md, "Code size"): no header over
# 400 lines, no function over 100 lines. A header that long holds more than
# one concept; a function that long is several stages that want names.
#
#   bash scripts/check_code_size.sh [SRC_DIR]      (default: src beside this script)
#
# Function extents come from Universal Ctags (its `end:` field: the line of a
# definition's closing brace), which parses C++ including in-class member
# definitions; lambdas count towards the function that holds them. Prints
# every breach as FILE:LINE and exits 1 when there is one, 0 otherwise; exits
# 2 when it cannot check (no Universal Ctags).
set -euo pipefail
src=${1:-"$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/src"}
max_header=400
max_function=100

if ! ctags --version 2>/dev/null | grep -q "Universal Ctags"; then
  echo "check_code_size: Universal Ctags is needed (Debian package universal-ctags; bash scripts/setup.sh --deps installs it)" >&2
  exit 2
fi
[ -d "$src" ] || { echo "check_code_size: no folder $src" >&2; exit 2; }

headers() {
  find "$src" \( -name '*.h' -o -name '*.cuh' \) -print | sort | while IFS= read -r h; do
    n=$(wc -l <"$h")
    if [ "$n" -gt "$max_header" ]; then echo "$h:1: header of $n lines (limit $max_header)"; fi
  done
}
functions() {
  local tags
  tags=$(ctags -R --languages=C++ --langmap=C++:+.cu.cuh --kinds-C++=f --fields=+ne -f - "$src")
  [ -n "$tags" ] || { echo "check_code_size: ctags found no function in $src" >&2; exit 2; }
  awk -F'\t' -v max="$max_function" '{
    start = ""; end = ""
    for (i = 4; i <= NF; ++i) {
      if ($i ~ /^line:/) start = substr($i, 6)
      if ($i ~ /^end:/) end = substr($i, 5)
    }
    if (start != "" && end != "" && end - start + 1 > max)
      printf "%s:%s: function %s of %d lines (limit %d)\n", $2, start, $1, end - start + 1, max
  }' <<<"$tags" | sort
}
report="$(headers)"$'\n'"$(functions)"
grep . <<<"$report" || true
breaches=$(grep -c . <<<"$report" || true)
if [ "$breaches" -gt 0 ]; then
  echo "check_code_size: $breaches over the limits in $src" >&2
  exit 1
fi
echo "check_code_size: every header within $max_header lines and every function within $max_function in $src"
