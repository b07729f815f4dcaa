#!/usr/bin/env bash
# The test suite N times over while every core is kept busy by other processes, as on a shared CI
# machine: each round runs every test of each build (Release, ASan+UBSan, TSan; see suites.sh).
# Builds first if needed (builds are not what this stresses). Prints the failures per test and
# exits 1 if any test failed in any round.
# Usage: tests/stress-run.sh N [SUITE...]   (default suites: release asan tsan)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
rounds=${1:?usage: tests/stress-run.sh N [SUITE...]}
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "N must be a positive number of rounds" >&2; exit 1; }
shift
deploy/install-deps.sh clang libclang-rt-14-dev iproute2
source tests/suites.sh
(($# > 0)) && suites=("$@")
for suite in "${suites[@]}"; do build_suite "$suite" >/dev/null; done

hogs=()
stop_hogs() { for pid in "${hogs[@]}"; do kill "$pid" 2>/dev/null || true; done; }
trap stop_hogs EXIT
for _ in $(seq "$jobs"); do
  yes >/dev/null &
  hogs+=($!)
done
echo "stress run: $rounds round(s) of ${suites[*]} with $jobs busy-loop processes hogging the cores"

logs=$(mktemp -d)
declare -A failed_runs=()
runs=0
started=$SECONDS
for round in $(seq "$rounds"); do
  for suite in "${suites[@]}"; do
    log=$logs/$suite-$round.log
    round_started=$SECONDS
    if test_suite "$suite" >"$log" 2>&1; then
      result="passed"
    else
      result="FAILED"
      # ctest lists failures as "  NNN - Name (Failed)"; keep a copy of the output.
      while read -r name; do
        failed_runs[$suite:$name]=$((${failed_runs[$suite:$name]:-0} + 1))
      done < <(grep -oP '^\s+[0-9]+ - \K\S+(?= \()' "$log")
      cp "$log" "build/stress-$suite-$round.log"
    fi
    runs=$((runs + 1))
    echo "round $round $suite: $result in $((SECONDS - round_started)) s ($(grep -oP '\d+ tests failed out of \d+|100% tests passed, 0 tests failed out of \d+' "$log" | tail -1))"
  done
done
rm -rf "$logs"
echo "=== $rounds round(s) in $((SECONDS - started)) s"
if ((${#failed_runs[@]} == 0)); then
  echo "no test failed in any round"
  exit 0
fi
echo "failures per test (of $rounds rounds; full output in build/stress-SUITE-ROUND.log):"
for key in "${!failed_runs[@]}"; do echo "  ${failed_runs[$key]}  $key"; done | sort -k2
exit 1
