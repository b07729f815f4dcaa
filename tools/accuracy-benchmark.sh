#!/usr/bin/env bash
# Accuracy benchmark: every built-in scene through the deterministic pipeline and the evaluator with
# the default parameters, then again without the noise filters ("/none" rows); one table (line
# heat-map P/R/F at 1% and 2% of the diagonal, segments per step, ids, lifetimes, tracking metrics,
# event rate), a row for the block segments and one for the whole lines of each run, and the whole
# lines' support by the segments.
# Usage: tools/accuracy-benchmark.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build/release}
out=${2:-$root/out/accuracy}
eval=$build/tools/evldt-eval/evldt-eval
[[ -x "$eval" ]] || { echo "build first: cmake --build $build (missing $eval)" >&2; exit 1; }
mkdir -p "$out"
printed_header=0
for filters in default none; do
  for scene in three-lines-fast circle-board boxes-6dof multi-speed monitor-hd noisy-boxes flicker-lamps night-boxes boxes-10s poster-10s tag-board; do
    step=10000
    [[ $scene == monitor-hd ]] && step=20000  # 1280x720: score every 20 ms to keep the run short
    name=$scene
    args=()
    if [[ $filters == none ]]; then name=$scene-none; args=(--filters none); fi
    "$eval" --scene "$scene" "${args[@]}" --step-us "$step" --log-level warn --json "$out/$name.json" \
      --lifetime-png "$out/$name-lifetimes.png" >"$out/$name.txt"
    if ((printed_header == 0)); then head -1 "$out/$name.txt"; printed_header=1; fi
    rate=$(python3 -c "import json; r = json.load(open('$out/$name.json'))['runs'][0]; print(f\"{r['events'] / r['scene_seconds'] / 1e6:.2f}\")")
    # A row for the segments and one for the whole lines of the same run.
    while IFS= read -r line; do
      [[ $filters == none ]] && line="${line/$scene/$scene/none}"
      [[ $line == "whole-line support"* || $line == "id switches"* ]] && { echo "$line"; continue; }
      echo "$line   ${rate} Mev/s"
    done < <(tail -n +2 "$out/$name.txt")
  done
done
echo "per-scene JSON and lifetime histograms in $out"
