#!/usr/bin/env bash
# The main job: installs missing packages, builds evldt, and runs line detection and tracking on a
# built-in simulated scene (default boxes-6dof), writing the segments, a video and a summary.
# Usage: deploy/demo.sh [SCENE] [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
scene=${1:-boxes-6dof}
out=${2:-$root/out/demo}
cd "$root"
deploy/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$(nproc)" --target evldt-offline evldt-sim evldt-eval
mkdir -p "$out"
bin=build/release/tools
"$bin/evldt-sim/evldt-sim" --scene "$scene" --out-dir "$out/recording" --quiet
"$bin/evldt-offline/evldt-offline" "$out/recording/events.raw" --output "$out/segments.csv" \
  --video "$out/segments.mp4" --summary-json "$out/summary.json" --show-ids
echo
echo "accuracy against the scene's exact edges (line heat-map, tolerance 1% and 2% of the diagonal):"
"$bin/evldt-eval/evldt-eval" --segments "$out/segments.csv" --scene "$scene" --json "$out/accuracy.json" \
  --lifetime-png "$out/lifetimes.png"
echo
echo "outputs in $out:"
echo "  recording/events.raw, recording/events.txt  simulated events (Prophesee EVT 3.0, ECD text)"
echo "  recording/ground_truth.csv                  exact visible edges over time"
echo "  segments.csv                                detected/tracked segments over time"
echo "  segments.mp4                                events (grey) and segments (yellow detected, green good, red bad)"
echo "  summary.json, accuracy.json, lifetimes.png   the summary, the accuracy, the segment lifetimes"
