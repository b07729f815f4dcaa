#!/usr/bin/env bash
# The whole test suite: installs missing packages, then
#   1. Release build, every test (ctest);
#   2. the whole suite again built with AddressSanitizer + UndefinedBehaviorSanitizer;
#   3. the whole suite again built with ThreadSanitizer;
#   4. each libFuzzer target for a few seconds from its corpus (clang).
# Usage: tests/run.sh [--quick]   (--quick: step 1 only)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
# What the tests need beyond the product: clang and libFuzzer for the fuzz targets, iproute2 for
# the multi-host test's network namespaces.
deploy/install-deps.sh clang libclang-rt-14-dev iproute2
jobs=$(nproc)
started=$SECONDS

suite() {  # suite NAME CMAKE_ARGS... : configure, build and run every test in build/NAME
  local name=$1
  shift
  echo "=== $name build and tests ($((SECONDS - started)) s so far)"
  cmake -S . -B "build/$name" -G Ninja "$@" >/dev/null
  cmake --build "build/$name" -j "$jobs"
  (cd "build/$name" && ctest --output-on-failure -j "$jobs" --timeout 300)
}

suite release -DCMAKE_BUILD_TYPE=Release
if [[ "${1:-}" != "--quick" ]]; then
  suite asan -DEVLDT_SANITIZE=address
  # LCM hands messages between threads through GLib, whose futex-based mutexes TSan cannot see:
  # accesses made inside those uninstrumented libraries are not judged (our own code still is).
  # TSan's default sleeps 1 s at exit while other threads (OpenCV's pool) live: the service tests
  # time how fast a process stops, which that sleep would measure instead.
  TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 ignore_noninstrumented_modules=1 atexit_sleep_ms=0" \
    suite tsan -DEVLDT_SANITIZE=thread
  echo "=== fuzz smoke run ($((SECONDS - started)) s so far)"
  tests/fuzz/run-fuzzers.sh 5
fi
echo "=== all tests passed in $((SECONDS - started)) s"
