#!/usr/bin/env bash
# What the pipeline computes, pinned: evldt-offline's segments and whole lines on every built-in
# scene (and two held-out motion seeds) must hash as in tests/data/offline-outputs.md5. A change
# meant to leave the output alone (a restructuring, an optimisation) must pass unchanged; a change
# meant to alter it updates the hashes with --update, in the same commit, and says why.
# Release builds only: a sanitizer build gives the same bytes (ASan did, in 108 s) but takes minutes
# (ThreadSanitizer far longer) for what the Release build already shows.
# Usage: offline_outputs_test.sh BUILD_DIR SOURCE_DIR BUILD_TYPE SANITIZER [--update]
set -euo pipefail
build=$1
src=$2
build_type=$3
sanitizer=$4
update=${5:-}
[[ $build_type == Release && -z $sanitizer ]] ||
  { echo "skipped: the outputs are pinned for the Release build (this is '$build_type', sanitizer '$sanitizer')"; exit 77; }
offline=$build/tools/evldt-offline/evldt-offline
hashes=$src/tests/data/offline-outputs.md5
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

run() {  # run NAME ARGS...
  local name=$1
  shift
  "$offline" "$@" -o "$work/$name.csv" --whole-lines "$work/$name-whole.csv" -q --log-level warn >/dev/null
}
names=()
for scene in three-lines-fast circle-board boxes-6dof multi-speed monitor-hd noisy-boxes flicker-lamps night-boxes boxes-10s poster-10s tag-board; do
  run "$scene" --scene "$scene" &
  names+=("$scene")
  (($(jobs -rp | wc -l) < $(nproc))) || wait -n
done
run boxes-ms31 --scene boxes-6dof --motion-seed 31 &
run tag-ms32 --scene tag-board --motion-seed 32 &
names+=(boxes-ms31 tag-ms32)
wait

(cd "$work" && md5sum -- *.csv) >"$work/hashes"
if [[ $update == --update ]]; then
  cp "$work/hashes" "$hashes"
  echo "updated $hashes ($(wc -l <"$hashes") files)"
  exit 0
fi
[[ $(wc -l <"$work/hashes") -eq $((2 * ${#names[@]})) ]] || { echo "FAIL: expected $((2 * ${#names[@]})) CSVs"; exit 1; }
if ! diff "$hashes" "$work/hashes"; then
  echo "FAIL: the offline outputs above changed (< pinned, > this build)."
  echo "If the change is meant: $0 $build $src Release '' --update, and say why in the commit."
  exit 1
fi
echo "ok: $(wc -l <"$hashes") CSVs of ${#names[@]} runs byte-identical to the pinned outputs"
