#!/usr/bin/env bash
# Install.ConsumerBuildsAgainstThePackage: installs this build into a
# temporary prefix, builds tests/install/consumer against it with
# find_package(throng), runs it, and checks throng.pc with pkg-config.
# When the Python module was built (THRONG_PYTHON, the interpreter, and
# THRONG_PYTHON_INSTALL_DIR set by CTest), it imports the installed module and
# steps a simulation.
# Any failure fails the test; nothing is skipped.
# Usage: consumer_test.sh BUILD_DIR SOURCE_DIR CMAKE CXX_COMPILER GENERATOR [LAUNCHER]
set -euo pipefail
build_dir=$1 source_dir=$2 cmake=$3 cxx=$4 generator=$5 launcher=${6:-}

work=$(mktemp -d "${TMPDIR:-/tmp}/throng-install-test.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

fail() { echo "FAIL: $*" >&2; exit 1; }

echo "== cmake --install $build_dir --prefix $prefix"
"$cmake" --install "$build_dir" --prefix "$prefix" > "$work/install.log" || { cat "$work/install.log"; fail "cmake --install"; }
for f in include/throng/core/buffer.h include/throng/io/scenario_yaml.h include/throng/sim/simulation.h \
         lib/libthrong_core.a lib/libthrong_io.a bin/throng \
         lib/cmake/throng/throngConfig.cmake lib/cmake/throng/throngConfigVersion.cmake \
         lib/cmake/throng/throngTargets.cmake lib/pkgconfig/throng.pc; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
# Only the library and the tool: no tests, benches or fuzz targets.
if find "$prefix" \( -name '*_tests' -o -name '*bench*' -o -name '*fuzz*' \) | grep .; then
  fail "test, bench or fuzz files installed"
fi

echo "== configure and build the consumer"
launcher_arg=()
[ -n "$launcher" ] && launcher_arg=(-DCMAKE_CXX_COMPILER_LAUNCHER="$launcher")
"$cmake" -S "$source_dir/tests/install/consumer" -B "$work/consumer" -G "$generator" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$cxx" "${launcher_arg[@]}" \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_PACKAGE_PREFER_CONFIG=ON > "$work/configure.log" 2>&1 \
  || { cat "$work/configure.log"; fail "consumer configure (find_package(throng))"; }
"$cmake" --build "$work/consumer" > "$work/build.log" 2>&1 || { cat "$work/build.log"; fail "consumer build"; }

echo "== run the consumer"
out=$("$work/consumer/throng_consumer") || fail "consumer exited $?"
echo "$out"
[[ $out =~ ^scenario=circle\ steps=10\ agents=([0-9]+)\ spec_agents=([0-9]+)$ ]] || fail "unexpected output: $out"
agents=${BASH_REMATCH[1]} spec_agents=${BASH_REMATCH[2]}
(( agents > 0 && agents == spec_agents )) || fail "agents=$agents, the scenario has $spec_agents"

echo "== pkg-config"
command -v pkg-config > /dev/null || fail "pkg-config not found"
flags=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs throng) || fail "pkg-config --cflags --libs throng"
echo "$flags"
incdir=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --variable=includedir throng)
[ -f "$incdir/core/buffer.h" ] || fail "includedir $incdir has no core/buffer.h"
[[ " $flags " == *" -I$incdir "* ]] || fail "--cflags lacks -I$incdir"
# Inline code in the headers must round as in the libraries (no fused multiply-adds).
[[ " $flags " == *" -ffp-contract=off "* ]] || fail "--cflags lacks -ffp-contract=off"
grep -q -- "-ffp-contract=off" "$prefix"/lib/cmake/throng/throngTargets.cmake ||
  fail "the exported targets do not ask consumers for -ffp-contract=off"
for lib in io path anim sim motion core; do
  [[ " $flags " == *" -lthrong_$lib "* ]] || fail "--libs lacks -lthrong_$lib"
done
# The libraries' order and dependencies: link the consumer's object with
# nothing but what pkg-config lists.
obj=$(find "$work/consumer" -name 'main.cpp.o' | head -1)
[ -n "$obj" ] || fail "consumer object not found"
libs=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --libs throng)
# shellcheck disable=SC2086
"$cxx" "$obj" -o "$work/consumer_pc" $libs || fail "link with pkg-config --libs throng"
out_pc=$("$work/consumer_pc") || fail "pkg-config-linked consumer exited $?"
[ "$out_pc" = "$out" ] || fail "pkg-config-linked consumer printed: $out_pc"
if [ -n "${THRONG_PYTHON:-}" ]; then
  echo "== import the installed Python module"
  pydir=$prefix/${THRONG_PYTHON_INSTALL_DIR:?THRONG_PYTHON_INSTALL_DIR unset}
  ls "$pydir"/throng*.so > /dev/null 2>&1 || fail "Python module not installed in $pydir"
  # From an empty folder: nothing of the build tree or source tree on the path.
  py_out=$(cd "$work" && PYTHONPATH="$pydir" "$THRONG_PYTHON" -c '
import throng
assert throng.__file__.startswith("'"$pydir"'"), throng.__file__
sim = throng.Simulation("circle", agents=20)
sim.step(10)
print(f"python: {throng.__name__} steps={sim.steps} agents={sim.agent_count} shape={sim.positions.shape}")
') || fail "import throng from $pydir"
  echo "$py_out"
  [ "$py_out" = "python: throng steps=10 agents=20 shape=(20, 2)" ] || fail "unexpected output: $py_out"
fi
echo "PASS"
