#!/usr/bin/env bash
# The main job: installs missing packages, builds evldt, and runs the distributed system on a
# built-in simulated scene (default boxes-6dof): evldt-camera -> evldt-lines -> evldt-viz (headless
# mp4) with lcm-logger recording the bus; then scores the recorded segments against the scene.
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
echo "accuracy of the live segments (recorded in run.lcmlog) against the scene's exact edges:"
build/release/tools/evldt-eval/evldt-eval --segments "$out/run.lcmlog" --scene "$scene" \
  --json "$out/accuracy.json" --lifetime-png "$out/lifetimes.png"
echo "  (also in $out: accuracy.json, lifetimes.png; offline and deterministic: tools/evldt-offline --scene $scene)"
