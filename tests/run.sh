#!/usr/bin/env bash
# The whole test suite: installs missing packages, then
#   1. Release build (warnings are errors), every test (ctest), the layout (clang-format) and
#      clang-tidy's checks;
#   2. the whole suite again built with AddressSanitizer + UndefinedBehaviorSanitizer;
#   3. the whole suite again built with ThreadSanitizer;
#   4. each libFuzzer target for a few seconds from its corpus (clang).
# Usage: tests/run.sh [--quick|--unit]
#   --quick: step 1 without the lint; --unit: the Release build and its GoogleTest cases and corpus replays only
#   (ctest -L unit: about 30 s once built; the loop to run while changing code, CONTRIBUTING.md)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
# What the tests need beyond the product: clang and libFuzzer for the fuzz targets, clang-format and clang-tidy, iproute2 for
# the multi-host test's network namespaces, Chromium for the web view's browser test, Node.js (npm)
# to check exported MCAP files against Foxglove's published schemas, ccache for quick rebuilds.
deploy/install-deps.sh clang clang-tidy clang-format libclang-rt-14-dev iproute2 chromium nodejs ccache
source tests/suites.sh
started=$SECONDS

mode=${1:-}
case $mode in
  "" | --quick | --unit) ;;
  *) echo "usage: tests/run.sh [--quick|--unit]" >&2; exit 1 ;;
esac
for suite in "${suites[@]}"; do
  echo "=== $suite build and tests ($((SECONDS - started)) s so far)"
  build_suite "$suite"
  if [[ $mode == --unit ]]; then
    test_suite "$suite" -L unit
    break
  fi
  test_suite "$suite"
  if [[ $suite == release && -z $mode ]]; then
    echo "=== clang-format and clang-tidy ($((SECONDS - started)) s so far)"
    tests/lint/format.sh
    tests/lint/clang_tidy.py build/release
  fi
  if [[ $mode == --quick ]]; then break; fi
done
if [[ -z $mode ]]; then
  echo "=== fuzz smoke run ($((SECONDS - started)) s so far)"
  tests/fuzz/run-fuzzers.sh 5
fi
echo "=== all tests passed in $((SECONDS - started)) s"
