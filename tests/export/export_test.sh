#!/usr/bin/env bash
# evldt-export: a live run recorded by lcm-logger (with undecodable messages on the
# camera's channels) written as MCAP in Foxglove's schemas, read back with evldt's own MCAP reader
# (mcap_channel_dump) and validated against Foxglove's published JSON schemas (npm @foxglove/schemas,
# with ajv; pinned in tests/export/package-lock.json, installed into the build folder once; skips,
# exit 77, when npm cannot install them). Bad inputs end with a clear error.
# Usage: export_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
export_tool=$build/tools/evldt-export/evldt-export
dump=$build/tests/mcap_channel_dump
url="udpm://239.255.76.67:7717?ttl=0"

checker=$build/tests/foxglove-schema-check
if ! cmp -s "$source_dir/tests/export/package-lock.json" "$checker/package-lock.json" 2>/dev/null || [[ ! -d $checker/node_modules ]]; then
  mkdir -p "$checker"
  cp "$source_dir/tests/export/package.json" "$source_dir/tests/export/package-lock.json" "$checker/"
  if ! (cd "$checker" && timeout 300 npm ci --no-audit --no-fund >npm.log 2>&1); then
    echo "skipped: npm could not install @foxglove/schemas and ajv (no registry?): $(tail -3 "$checker/npm.log")"
    rm -rf "$checker/node_modules"
    exit 77
  fi
fi
cp "$source_dir/tests/export/validate_foxglove.mjs" "$checker/"

# --- a live run, recorded ---------------------------------------------------------------------
"${logger[@]}" --lcm-url="$url&$logger_buffer" -f -q "$work/run.lcmlog" &
logger_pid=$!
# With a calibration (one that keeps every pixel), so that the camera goes into the file too.
"$lines" --lcm-url "$url" --log-period-s 0.2 --calibration "$source_dir/tests/data/calibration/pinhole_240x180.yaml" \
  >"$work/lines.out" 2>"$work/lines.err" &
lines_pid=$!
wait_logger_ready "$url" "$work/run.lcmlog" TEST_MARKER
wait_ready "$work/lines.err" evldt-lines
"$junk" "$url" EVENTS_CAM0 3
"$junk" "$url" LINES_CAM0 2
"$camera" --lcm-url "$url" --scene boxes-6dof --duration-s 1 -q >"$work/camera.out" 2>"$work/camera.err"
check "camera exits 0" test $? -eq 0
batches=$(field "$work/camera.out" 'batches')
log_holds_all "$url" "$work/run.lcmlog" EVENTS_CAM0 "$((batches + 3))"
wait_until "whole lines in the log" log_holds "$url" "$work/run.lcmlog" WHOLE_LINES_CAM0 5
wait_until "the camera in the log" log_holds "$url" "$work/run.lcmlog" CAMERA_INFO_CAM0 1
stops_promptly "$lines_pid" >/dev/null
wait_until "a statistics message in the log" log_holds "$url" "$work/run.lcmlog" EVLDT_STATS 1
stops_promptly "$logger_pid" INT >/dev/null

# --- export, read back, validate ----------------------------------------------------------------
"$export_tool" "$work/run.lcmlog" "$work/run.mcap" --image-hz 20 >"$work/export.out" 2>"$work/export.err"
check "evldt-export exits 0" test $? -eq 0
cat "$work/export.out"
pictures=$(field "$work/export.out" 'written')
check "segment lists, whole-line lists and the camera written" \
  grep -qP 'pictures, [1-9][0-9]* segment lists, [1-9][0-9]* whole-line lists, [1-9][0-9]* statistics, [1-9][0-9]* camera calibrations' "$work/export.out"
check "the undecodable messages counted (3 batches, 2 lists)" grep -q "skipped   5 undecodable" "$work/export.out"
check "the undecodable messages reported" grep -q "5 undecodable messages of camera cam0 skipped" "$work/export.err"
for topic in events segments whole_lines stats camera_info; do
  "$dump" "$work/run.mcap" "/cam0/$topic" >"$work/$topic.dump" 2>"$work/$topic.err"
  check "evldt's MCAP reader reads /cam0/$topic back" test $? -eq 0
done
# Pictures at 20 Hz of recording time: picture k no earlier than k periods after the first, and as
# many as the recording's span allows (lcm-logger's clock: a loaded machine stretches the 1 s run).
picture_times() { tail -n +3 "$work/events.dump" | grep -oP '"timestamp": \{"sec": \K[0-9]+, "nsec": [0-9]+' | awk -F', "nsec": ' '{ printf "%.6f\n", $1 + $2 * 1e-9 }'; }
read -r early most < <(picture_times | awk 'NR == 1 { first = $1 } { late = $1 - first - (NR - 1) * 0.05; if (NR == 1 || late < least) least = late; last = $1 }
  END { printf "%d %d\n", least < -1e-6, int((last - first) / 0.05 + 1e-6) + 1 }')
check "pictures at 20 Hz: ${pictures:-none} of at most ${most:-?}, none early" \
  awk -v n="${pictures:-0}" -v most="${most:-0}" -v early="${early:-1}" 'BEGIN { exit !(n >= 15 && n <= most && early == 0) }'
check "the pictures' channel is foxglove.CompressedImage in JSON" grep -q "^foxglove.CompressedImage jsonschema json $pictures\$" "$work/events.dump"
check "the segments' channel is foxglove.ImageAnnotations" grep -q "^foxglove.ImageAnnotations jsonschema json " "$work/segments.dump"
check "the camera is foxglove.CameraCalibration with the calibration's K" \
  grep -qP '"K": \[199.1, 0, 119.5, 0, 198.8, 89.5, 0, 0, 1\]' "$work/camera_info.dump"
check "whole lines carry their ids as texts" grep -qP '"texts": \[\{"timestamp": \{"sec": [0-9]+, "nsec": [0-9]+\}, "position"' "$work/whole_lines.dump"
(cd "$checker" && node validate_foxglove.mjs "$work"/{events,segments,whole_lines,stats,camera_info}.dump) >"$work/validate.out" 2>&1
check "every message valid against Foxglove's published schemas and the file's own" test $? -eq 0
cat "$work/validate.out"
"$dump" "$work/run.mcap" /cam0/nothing >/dev/null 2>"$work/nothing.err"
check "a channel not in the file is named in the reader's error" grep -q "no channel /cam0/nothing (channels: /cam0/events" "$work/nothing.err"

# --- bad inputs --------------------------------------------------------------------------------
head -c 5000 /dev/urandom >"$work/garbage.lcmlog"
"$export_tool" "$work/garbage.lcmlog" "$work/garbage.mcap" >/dev/null 2>"$work/garbage.err"
status=$?
check "a file that is no LCM log is refused (exit $status)" test "$status" -ne 0 -a "$status" -lt 128
check "... naming the file" grep -q "garbage.lcmlog" "$work/garbage.err"
head -c 20000 "$work/run.lcmlog" >"$work/cut.lcmlog"
"$export_tool" "$work/cut.lcmlog" "$work/cut.mcap" >"$work/cut.out" 2>"$work/cut.err"
status=$?
check "a log cut short exports what it holds, or says why not (exit $status, no crash)" test "$status" -lt 128
# A log damaged in the middle (64 zeroed bytes over a record's header: LCM's own reader skipped them
# without a word) is read past the damage, and all three tools that read logs say what they skipped.
# (Zeroed bytes inside a message's data cannot be told from data: LCM messages carry no checksum.)
cp "$work/run.lcmlog" "$work/damaged.lcmlog"
size=$(stat -c %s "$work/damaged.lcmlog")
middle=$(LC_ALL=C grep -obUaP '\xED\xA1\xDA\x01' "$work/damaged.lcmlog" | awk -F: -v half=$((size / 2)) '$1 >= half { print $1; exit }')
dd if=/dev/zero of="$work/damaged.lcmlog" bs=1 seek="${middle:-0}" count=64 conv=notrunc status=none
"$export_tool" "$work/damaged.lcmlog" "$work/damaged.mcap" >"$work/damaged.out" 2>"$work/damaged.err"
check "evldt-export reads a damaged log to its end (exit $?)" grep -qP "written   [1-9][0-9]* pictures" "$work/damaged.out"
check "... and counts the damage in its summary" grep -qP "damage    [1-9][0-9]* bytes in 1 place" "$work/damaged.out"
check "... and says it" grep -q "damaged.lcmlog: [0-9]* damaged bytes skipped in 1 place(s), the first at byte" "$work/damaged.err"
"$offline" "$work/damaged.lcmlog" -q -o "$work/damaged.csv" >/dev/null 2>"$work/damaged_offline.err"
check "evldt-offline on a damaged log says what it skipped" grep -q "damaged bytes skipped" "$work/damaged_offline.err"
"$eval_tool" --segments "$work/damaged.lcmlog" --scene boxes-6dof --duration-s 1 >/dev/null 2>"$work/damaged_eval.err"
check "evldt-eval on a damaged log says what it skipped" grep -q "damaged bytes skipped" "$work/damaged_eval.err"
head -c $((size - 7)) "$work/run.lcmlog" >"$work/cut_end.lcmlog"
"$export_tool" "$work/cut_end.lcmlog" "$work/cut_end.mcap" >"$work/cut_end.out" 2>"$work/cut_end.err"
check "a log whose last record is cut short says so" grep -q "cut_end.lcmlog: the last record (at byte [0-9]*) is cut short" "$work/cut_end.err"
"$export_tool" "$work/run.lcmlog" "$work/other.mcap" --camera front >/dev/null 2>"$work/other.err"
check "a camera not in the log is refused" grep -q "no valid event batch on EVENTS_FRONT" "$work/other.err"
"$export_tool" "$work/run.lcmlog" "$work/no/such/folder/x.mcap" >/dev/null 2>"$work/folder.err"
check "an output that cannot be created is named" grep -q "cannot create '$work/no/such/folder/x.mcap'" "$work/folder.err"
finish
