#!/usr/bin/env bash
# The LCM throughput benchmark end to end at its smallest: one short speed on a small scene; the
# run is parsed into every column and the JSON (speed itself is never asserted; the live F@1% is
# a number, scored from the recorded segment lists).
# Usage: lcm_bench_smoke_test.sh LCM_THROUGHPUT_BENCH BUILD_DIR
set -euo pipefail
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$1" --build "$2" --scene boxes-6dof --seconds 2 --speeds 1 --max-p99-ms 1000 --json "$work/lcm.json" | tee "$work/out.txt"
grep -qP '^1 +0\.[0-9]+ +0 of [1-9][0-9]* +[0-9]+ \([0-9.]+%\) +[0-9]+% +[0-9]+% +[1-9][0-9]* +9\.[0-9]+ +[0-9.]+ / [0-9.]+ +[0-9.]+ +0\.[0-9]+$' "$work/out.txt"
grep -qP '"batches_lost": 0,' "$work/lcm.json"
grep -qP '"batches_shed": [0-9]+, "events_shed": [0-9]+,' "$work/lcm.json"
grep -qP '"latency_settled_p99_ms": [0-9.]+,' "$work/lcm.json"  # 2 s: a second of it settled
grep -qP '"live_f_1pct": 0\.[0-9]*[1-9]' "$work/lcm.json"
grep -qP '"threads": [1-9]' "$work/lcm.json"
grep -qP '"best_mev_s": 0\.[0-9]*[1-9]' "$work/lcm.json"
echo "ok"
