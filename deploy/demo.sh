#!/usr/bin/env bash
# The main job: installs missing packages, builds evldt, and runs the distributed system on a
# built-in simulated scene (default boxes-6dof): evldt-camera -> evldt-lines -> evldt-viz (headless
# mp4 with whole lines and their ids over the segments) with lcm-logger recording the bus; then
# scores both levels the bus carried, the block segments and the whole lines, against the scene.
# Usage: deploy/demo.sh [SCENE] [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
scene=${1:-boxes-6dof}
out=${2:-$root/out/demo}
cd "$root"
deploy/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$(nproc)"
deploy/run-system.sh --out "$out" -- --scene "$scene" --quiet
echo
echo "accuracy of the live lines (recorded in run.lcmlog) against the scene's exact edges:"
eval_tool=build/release/tools/evldt-eval/evldt-eval
"$eval_tool" --segments "$out/run.lcmlog" --lcm-channel LINES_CAM0 --label segments --scene "$scene" \
  --json "$out/accuracy-segments.json" --lifetime-png "$out/lifetimes-segments.png" --log-level warn
"$eval_tool" --segments "$out/run.lcmlog" --lcm-channel WHOLE_LINES_CAM0 --label "whole lines" --scene "$scene" \
  --json "$out/accuracy-whole-lines.json" --lifetime-png "$out/lifetimes-whole-lines.png" --log-level warn | tail -n +2
echo "  (also in $out: accuracy-*.json, lifetimes-*.png; offline and deterministic: tools/evldt-offline --scene $scene)"
