#!/usr/bin/env bash
# Identity benchmark: the scenes where line ids break (fast motion, dense structure), each through
# evldt-eval at the defaults, then a table of the whole lines' and the segments' F@1%, IDF1, ids,
# id switches by cause, and how well their normal velocity is estimated. The first set is what the
# parameters were chosen on; the held-out set (other motion seeds) was not looked at while choosing.
# Usage: tools/identity-benchmark.sh [BUILD_DIR] [OUT_DIR] [--held-out-only|--tuned-only]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build/release}
out=${2:-$root/out/identity}
which=${3:-}
eval=$build/tools/evldt-eval/evldt-eval
[[ -x "$eval" ]] || { echo "build first: cmake --build $build (missing $eval)" >&2; exit 1; }
mkdir -p "$out"
tuned=(
  "boxes-6dof"
  "boxes-10s --motion-seed 11"
  "three-lines-fast"
  "monitor-hd"
  "multi-speed"
  "poster-10s --motion-seed 9"
  "circle-board"
  "tag-board"
)
held_out=(
  "three-lines-fast --motion-seed 3"
  "three-lines-fast --motion-seed 41"
  "monitor-hd --motion-seed 13"
  "multi-speed --seed 42"
  "circle-board --motion-seed 16"
  "tag-board --motion-seed 12"
  "poster-10s --motion-seed 19"
  "boxes-6dof --seed 2 --motion-seed 21"
)
runs=()
[[ $which != --held-out-only ]] && runs+=("${tuned[@]}")
[[ $which != --tuned-only ]] && runs+=("${held_out[@]}")
name_of() { echo "$1" | tr -d -- '-' | tr ' ' '_'; }
for run in "${runs[@]}"; do
  # shellcheck disable=SC2086 # the run's words are its arguments
  echo "$eval --scene $run --log-level warn --json $out/$(name_of "$run").json >$out/$(name_of "$run").txt"
done | xargs -P "$(nproc)" -I{} bash -c {}
python3 - "$out" "${runs[@]}" <<'PY'
import json, sys
out, runs = sys.argv[1], sys.argv[2:]
def name_of(run): return run.replace('-', '').replace(' ', '_')
print(f"{'run':36} {'level':8} {'F@1%':>6} {'IDF1':>6} {'ids':>5} {'id_sw':>5}  {'other':>5} {'off':>5} {'back':>5} {'again':>5} {'taken':>5}  {'vel_err':>7} {'vel_rel':>7}")
for run in runs:
    report = json.load(open(f"{out}/{name_of(run)}.json"))
    for r in report['runs']:
        level = 'whole' if r['run'].endswith(' whole') else 'segments'
        t = r['tracking']; c = t.get('id_switch_causes', {})
        f = r['accuracy'][0]['f']
        fmt = lambda v, d=3: 'n/a' if v is None else f"{v:.{d}f}"
        print(f"{run:36} {level:8} {fmt(f):>6} {fmt(t['idf1']):>6} {r['lifetime']['ids']:>5} {t['id_switches']:>5}  "
              f"{c.get('to_other_edge', '-'):>5} {c.get('off_edge', '-'):>5} {c.get('returned', '-'):>5} {c.get('redetected', '-'):>5} {c.get('taken_over', '-'):>5}  "
              f"{fmt(t.get('vel_err_med'), 1):>7} {fmt(t.get('vel_rel_med')):>7}")
PY
