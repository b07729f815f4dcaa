#!/usr/bin/env bash
# The whole test suite: installs missing packages, builds Release and runs every test, then builds
# the concurrent tests with ThreadSanitizer and runs them. Usage: tests/run.sh [--no-tsan]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
deploy/install-deps.sh
jobs=$(nproc)

cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$jobs"
(cd build/release && ctest --output-on-failure -j "$jobs" --timeout 300)

if [[ "${1:-}" != "--no-tsan" ]]; then
  # ThreadSanitizer over the suites that run threads (the real-time engine and the service nodes);
  # the rest is single-threaded.
  cmake -S . -B build/tsan -G Ninja -DEVLDT_SANITIZE=thread >/dev/null
  cmake --build build/tsan -j "$jobs" --target test_lines test_nodes
  export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1"
  build/tsan/tests/test_lines --gtest_filter='RealtimeEngine.*:Pipeline.*'
  # LCM hands messages between threads through GLib, whose futex-based mutexes TSan cannot see:
  # accesses made inside those uninstrumented libraries are not judged (our own code still is).
  TSAN_OPTIONS="$TSAN_OPTIONS ignore_noninstrumented_modules=1" build/tsan/tests/test_nodes
fi
