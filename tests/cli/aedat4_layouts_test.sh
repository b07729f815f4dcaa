#!/usr/bin/env bash
# AEDAT 4.0 as each writer lays it out: the same scene written by tests/support/aedat4_fixture in
# DV's layout and in the aedat library's (each FlatBuffer finished plain, its size put in front), in
# every compression, gives the same segments through evldt-offline, the same score against its
# frames through evldt-eval --frames-gt, and the same events through evldt-camera.
# Usage: aedat4_layouts_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
fixture=$build/tests/aedat4_fixture
offline=$build/tools/evldt-offline/evldt-offline
eval=$build/tools/evldt-eval/evldt-eval
camera=$build/services/evldt-camera/evldt-camera
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

for compression in none lz4 zstd; do
  for layout in dv aedat-library; do
    "$fixture" "$work/$layout.aedat4" "$layout" "$compression" || fail "writing the $layout fixture ($compression)"
    "$offline" "$work/$layout.aedat4" -q -o "$work/$layout.csv" >/dev/null 2>"$work/$layout.offline.err" ||
      fail "evldt-offline on the $layout layout ($compression): $(cat "$work/$layout.offline.err")"
    "$eval" --segments "$work/$layout.csv" --frames-gt "$work/$layout.aedat4" --visible-only >"$work/$layout.eval" \
      2>"$work/$layout.eval.err" || fail "evldt-eval --frames-gt on the $layout layout ($compression): $(cat "$work/$layout.eval.err")"
    grep -q "14 ground-truth steps scored" "$work/$layout.eval.err" || fail "14 frames of the $layout layout: $(cat "$work/$layout.eval.err")"
    "$camera" "$work/$layout.aedat4" --lcm-url memq:// >"$work/$layout.camera" 2>&1 ||
      fail "evldt-camera on the $layout layout ($compression): $(cat "$work/$layout.camera")"
  done
  [[ $(wc -l <"$work/dv.csv") -gt 100 ]] || fail "the DV layout gave almost no segments ($compression)"
  cmp -s "$work/dv.csv" "$work/aedat-library.csv" || fail "evldt-offline: the layouts give other segments ($compression)"
  same_run() { sed -E 's/^(dv|aedat-library)\.csv/RUN/; s/ +/ /g' "$1"; }
  diff <(same_run "$work/dv.eval") <(same_run "$work/aedat-library.eval") >&2 ||
    fail "evldt-eval --frames-gt: the layouts score differently ($compression)"
  events=$(grep -E '^  events ' "$work/dv.camera")
  [[ -n $events && $events == $(grep -E '^  events ' "$work/aedat-library.camera") ]] ||
    fail "evldt-camera: $(cat "$work/dv.camera" "$work/aedat-library.camera")"
  echo "ok: $compression: the aedat library's layout reads as DV's through evldt-offline, evldt-eval --frames-gt and evldt-camera"
done
