#!/usr/bin/env bash
# The performance benchmark in one command (about 5 minutes here): builds Release, then measures the
# core at every sensor size (evldt-bench), the LCM path end to end (lcm-throughput-bench.sh) and the
# Python module's pipeline against evldt-offline (python-bench.py).
# Figures go to the terminal and to out/bench/core.json and out/bench/lcm-*.json.
# Usage: tools/benchmark.sh [--quick]   (--quick: fewer repeats and 3 s per LCM speed)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
deploy/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$(nproc)" --target evldt-bench evldt-camera evldt-lines evldt-sim evldt-offline evldt_python
mkdir -p out/bench
core_args=()
lcm_args=()
if [[ "${1:-}" == "--quick" ]]; then
  core_args=(--repeats 3 --min-time-ms 30)
  lcm_args=(--seconds 3)
fi
build/release/tools/evldt-bench/evldt-bench "${core_args[@]}" --json out/bench/core.json
echo
# HD passes split over a worker pool of two threads (the figures above are on one).
build/release/tools/evldt-bench/evldt-bench "${core_args[@]}" --sizes 1280x720 --threads 2 --json out/bench/core-1280x720-2threads.json
echo
tools/lcm-throughput-bench.sh "${lcm_args[@]}" --scene three-lines-fast --speeds "0.5 1 2 2.6 3 4" --json out/bench/lcm-640x480.json
echo
tools/lcm-throughput-bench.sh "${lcm_args[@]}" --scene monitor-hd --speeds "0.1 0.25 0.5 1" --lines-arg --threads=1 \
  --json out/bench/lcm-1280x720.json
echo
tools/lcm-throughput-bench.sh "${lcm_args[@]}" --scene monitor-hd --speeds "0.1 0.25 0.5 1" --lines-arg --threads=2 \
  --json out/bench/lcm-1280x720-2threads.json
echo
# The Python module's pipeline against evldt-offline on the same recording.
/usr/bin/python3 tools/python-bench.py --build build/release
