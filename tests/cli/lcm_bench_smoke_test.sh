#!/usr/bin/env bash
# The LCM throughput benchmark end to end at its smallest: one short speed on a small scene; the
# run is parsed into every column and the JSON (speed itself is never asserted; the live F@1% is
# a number, scored from the recorded segment lists).
# Usage: lcm_bench_smoke_test.sh LCM_THROUGHPUT_BENCH BUILD_DIR
set -euo pipefail
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$1" --build "$2" --scene boxes-6dof --seconds 2 --speeds 1 --max-p99-ms 1000 --json "$work/lcm.json" | tee "$work/out.txt"
grep -qP '^1 +0\.[0-9]+ +0 of [1-9][0-9]* +[0-9]+/[0-9]+ \([0-9.]+%\) +[0-9]+% +[0-9]+% +[1-9][0-9]* +9\.[0-9]+ +[0-9.]+ / [0-9.]+ +[0-9.]+ +0\.[0-9]+$' "$work/out.txt"
grep -qP '"batches_lost": 0,' "$work/lcm.json"
grep -qP '"batches_shed": [0-9]+, "batches_thinned": [0-9]+, "events_shed": [0-9]+,' "$work/lcm.json"
grep -qP '"latency_settled_p99_ms": [0-9.]+,' "$work/lcm.json"  # 2 s: a second of it settled
grep -qP '"live_f_1pct": 0\.[0-9]*[1-9]' "$work/lcm.json"
grep -qP '"threads": [1-9]' "$work/lcm.json"
grep -qP '"best_mev_s": 0\.[0-9]*[1-9]' "$work/lcm.json"
# Repeats: the speeds run again in turn, then the median of each figure per speed.
"$1" --build "$2" --scene boxes-6dof --seconds 1 --speeds 1 --repeats 2 --no-f --max-p99-ms 1000 --json "$work/repeats.json" | tee "$work/repeats.txt"
[[ $(grep -c '^run [12] of 2$' "$work/repeats.txt") -eq 2 ]] || { echo "FAILED: runs not announced"; exit 1; }
grep -qP '^1 +[0-9.]+% +[0-9.]+% +[0-9.]+ +([0-9.]+|nan) +nan +0 of 2$' "$work/repeats.txt" || { echo "FAILED: medians row"; exit 1; }
[[ $(grep -oP '"repeat": [12],' "$work/repeats.json" | wc -l) -eq 2 ]] || { echo "FAILED: runs in the JSON"; exit 1; }
grep -qP '"medians": \[\s*\{"speed": 1, "lines_cpu_pct": [0-9.]+, .*"live_f_1pct": null, "runs_with_loss": 0\}' <(tr -d '\n' <"$work/repeats.json")
if "$1" --build "$2" --repeats 0 2>"$work/err.txt"; then echo "FAILED: --repeats 0 accepted"; exit 1; fi
grep -q -- '--repeats takes a positive whole number' "$work/err.txt"
echo "ok"
