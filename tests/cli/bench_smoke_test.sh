#!/usr/bin/env bash
# evldt-bench end to end at its smallest: every figure of one size is measured, positive and written
# to the JSON (speed itself is never asserted: this machine is shared and noisy).
# Usage: bench_smoke_test.sh EVLDT_BENCH
set -euo pipefail
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$1" --sizes 240x180 --repeats 1 --min-time-ms 1 --window-ms 50 --json "$work/bench.json" >"$work/out.txt"
cat "$work/out.txt"
grep -q '^240x180 *boxes-6dof' "$work/out.txt"
for key in storage_mev_s receive_mev_s detect_hz track_hz filters_mev_s rectify_mev_s pipeline_mev_s lattice_mb peak_rss_mb active_points lines_tracked; do
  value=$(grep -oP "\"$key\": \K[0-9.e+-]+" "$work/bench.json")
  awk -v v="$value" 'BEGIN { exit !(v > 0) }' || { echo "FAILED: $key = '$value'"; exit 1; }
done
for timing in filters_setup_ms storage_by_block_ns_per_event storage_bound_ns_per_event filters_bound_ns_per_event; do
  value=$(grep -oP "\"$timing\": \\{\"unit\": \"[a-z]+\", \"median\": \K[0-9.e+-]+" "$work/bench.json")
  awk -v v="$value" 'BEGIN { exit !(v > 0) }' || { echo "FAILED: $timing = '$value'"; exit 1; }
done
# The per-event path against its memory bound: a row of nine positive figures.
grep -qP '^240x180( +[0-9]+\.[0-9]+){9}$' "$work/out.txt" || { echo "FAILED: per-event path table"; exit 1; }
# Decoding speed: the same events in each of the five file formats, every one read whole.
"$1" --decode --repeats 1 >"$work/decode.txt"
cat "$work/decode.txt"
[[ $(grep -cP '^sample\S* +2120987 events +[0-9.]+ Mev/s' "$work/decode.txt") -eq 5 ]] || { echo "FAILED: decode table"; exit 1; }
# Another filter chain is timed when asked for, and an unknown one is refused by name.
"$1" --sizes 240x180 --repeats 1 --min-time-ms 1 --window-ms 50 --filters refractory,hot-pixel >"$work/chain.txt"
grep -q 'filters: refractory,hot-pixel$' "$work/chain.txt" || { echo "FAILED: chain not named"; exit 1; }
if "$1" --sizes 240x180 --filters refractory,bogus 2>"$work/err.txt"; then echo "FAILED: bad filter accepted"; exit 1; fi
grep -q "unknown filter 'bogus'" "$work/err.txt"
# A wrong flag is refused with the flag named.
if "$1" --sizes 123x45 2>"$work/err.txt"; then echo "FAILED: bad size accepted"; exit 1; fi
grep -q -- '--sizes' "$work/err.txt"
echo "ok"
