#!/usr/bin/env bash
# The consumer SDK: evldt installed to a prefix; examples/consumer, a separate CMake
# project, configured with find_package(evldt) against it and built; the same program built with
# pkg-config's flags; both run against a live camera -> lines system on loopback and must print the
# segments and whole lines they receive.
# Usage: consumer_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
url="udpm://239.255.76.67:7720?ttl=0"

cmake --install "$build" --prefix "$work/prefix" >"$work/install.out" 2>&1
check "cmake --install to a prefix" test $? -eq 0
check "the message types' headers are installed" test -f "$work/prefix/include/evldt/segment_list_t.hpp"
check "the SDK's header is installed" test -f "$work/prefix/include/evldt/client/line_subscriber.hpp"
cmake -S "$source_dir/examples/consumer" -B "$work/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" >"$work/configure.out" 2>&1
check "examples/consumer configures with find_package(evldt)" test $? -eq 0
cmake --build "$work/consumer" >"$work/build.out" 2>&1
check "... and builds" test $? -eq 0
pc_dir=$(dirname "$(find "$work/prefix" -name evldt.pc | head -1)")
flags=$(PKG_CONFIG_PATH=$pc_dir pkg-config --cflags --libs evldt)
include_dir=$(grep -oP -- '-I\K\S+' <<<"$flags")
check "pkg-config gives evldt's flags ($flags)" test -f "$include_dir/evldt/client/line_subscriber.hpp"
# shellcheck disable=SC2086
g++ -std=c++17 -O1 "$source_dir/examples/consumer/print_lines.cpp" -o "$work/print_lines_pc" $flags 2>"$work/pc_build.err"
check "... with which the example builds too" test $? -eq 0
cat "$work/configure.out" "$work/build.out" "$work/pc_build.err" | tail -5

"$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines.out" 2>"$work/lines.err" &
lines_pid=$!
wait_ready "$work/lines.err" evldt-lines
timeout 120 "$work/consumer/print_lines" cam0 "$url" 30 >"$work/cmake_consumer.out" 2>&1 &
cmake_consumer=$!
timeout 120 "$work/print_lines_pc" cam0 "$url" 30 >"$work/pc_consumer.out" 2>&1 &
pc_consumer=$!
wait_until "the consumers to subscribe" bash -c "grep -q '^ready' '$work/cmake_consumer.out' && grep -q '^ready' '$work/pc_consumer.out'"
"$camera" --lcm-url "$url" --scene boxes-6dof --duration-s 1 -q >"$work/camera.out" 2>&1
wait "$cmake_consumer"
check "the consumer built with CMake received 30 lists and ended" test $? -eq 0
wait "$pc_consumer"
check "the consumer built with pkg-config received 30 lists and ended" test $? -eq 0
stops_promptly "$lines_pid" >/dev/null
head -5 "$work/cmake_consumer.out"
for out in cmake_consumer pc_consumer; do
  check "$out printed segment lists with lines" grep -qP '^segments cam0 t_us [0-9]+ lines [1-9]' "$work/$out.out"
  check "$out printed whole-line lists" grep -qP '^whole-lines cam0 t_us [0-9]+ lines [0-9]+' "$work/$out.out"
  check "$out printed the lines" grep -qP '^  id [0-9]+ \([0-9.]+, [0-9.]+\) - \([0-9.]+, [0-9.]+\) score [0-9.]+$' "$work/$out.out"
done
finish
