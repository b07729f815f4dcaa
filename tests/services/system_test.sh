#!/usr/bin/env bash
# The distributed system end to end, real processes over UDP multicast on loopback (ttl=0):
# camera -> lines -> viz + lcm-logger; the log replayed with lcm-logplayer into a second lines
# service; junk on the event channel; SIGTERM stopping each service; lcm-spy's decoding of the log.
# Usage: system_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
# Ports of this test only, so concurrent tests never hear each other.
url="udpm://239.255.76.67:7711?ttl=0"
replay_url="udpm://239.255.76.67:7712?ttl=0"
scene=(--scene boxes-6dof --duration-s 1.5)

# --- live run ---------------------------------------------------------------------------------
"${logger[@]}" --lcm-url="$url&$logger_buffer" -f -q "$work/live.lcm" &
logger_pid=$!
# With a calibration that keeps every pixel: the same lines, and the camera on CAMERA_INFO_CAM0.
"$lines" --lcm-url "$url" --log-period-s 0 --calibration "$source_dir/tests/data/calibration/pinhole_240x180.yaml" \
  >"$work/lines.out" 2>"$work/lines.err" &
lines_pid=$!
"$viz" --lcm-url "$url" --headless --video "$work/viz.mp4" --png-dir "$work/png" --png-period-s 0.5 --fps 20 \
  >"$work/viz.out" 2>"$work/viz.err" &
viz_pid=$!
"$probe" "$url" cam0 600 >"$work/probe.out" &
probe_pid=$!
wait_logger_ready "$url" "$work/live.lcm" TEST_MARKER
wait_ready "$work/lines.err" evldt-lines
wait_ready "$work/viz.err" evldt-viz
wait_until "the probe to subscribe" grep -q '^ready' "$work/probe.out"
"$junk" "$url" EVENTS_CAM0 8
"$camera" --lcm-url "$url" "${scene[@]}" -q >"$work/camera.out" 2>"$work/camera.err"
check "camera exits 0" test $? -eq 0
batches=$(field "$work/camera.out" 'batches')
check "evldt-lines published a segment list that includes the last batch" \
  wait_until "a segment list including batch $((batches - 1))" probe_heard_batch "$work/probe.out" $((batches - 1))
log_complete=1
# The 8 junk messages were sent on the same channel before the camera started.
log_holds_all "$url" "$work/live.lcm" EVENTS_CAM0 "$((batches + 8))" || log_complete=0
check "evldt-lines stops promptly at SIGTERM" stops_promptly "$lines_pid"
check "evldt-viz stops promptly at SIGTERM" stops_promptly "$viz_pid"
stops_promptly "$logger_pid" INT
kill "$probe_pid"
cat "$work/camera.out" "$work/lines.out" "$work/viz.out"

check "lines received every batch ($batches)" grep -q "batches   $batches received, 0 lost" "$work/lines.out"
# The stock lcm-logger drops messages past a 30-message queue when it waits for a core; when the
# machine starves it, what evldt answers for is that every batch was sent and received, and the
# checks on the recording are skipped (they need the whole log).
if ((log_complete)); then
  echo "ok: lcm-logger recorded every batch"
else
  echo "note: lcm-logger missed batches on a starved machine; the checks on the log are skipped"
fi
# Whether evldt-lines kept up: 1.5 s of events make 750 tracking rounds of 2 ms. When other work
# starves it (a noisy shared VM: 420-630 rounds seen), its live output lags and is judged only
# against a floor; when it keeps up, against the offline run.
rounds=$(tracking_rounds "$work/lines.out")
kept_up=$((${rounds:-0} * 10 >= 750 * 9))
echo "evldt-lines ran ${rounds:-?} of 750 tracking rounds"
check "junk counted as 8 invalid messages" grep -q " 8 invalid messages" "$work/lines.out"
check "lines stored events" test "$(field "$work/lines.out" 'events')" -gt 100000
check "viz drew frames into the mp4" test -s "$work/viz.mp4"
check "viz wrote PNG snapshots" test "$(ls "$work/png" | wc -l)" -ge 2
check "viz received the segment lists" grep -qP "received  $batches batches \(0 lost, 8 invalid\), [1-9][0-9]* segment lists \(0 invalid\), [1-9]" "$work/viz.out"

# The Python example prints the recorded segment lists (where the Python module is built).
if [[ -d $build/python/evldt ]]; then
  PYTHONPATH=$build/python /usr/bin/python3 "$source_dir/libs/python/examples/print_log_segments.py" "$work/live.lcm" \
    >"$work/python_log.out" 2>&1
  tail -2 "$work/python_log.out"
  check "the Python example reads the log's segment lists" grep -qP '^[1-9][0-9]* segment lists on LINES_CAM0$' "$work/python_log.out"
fi

# The recorded events are exactly the simulated ones: offline on the log = offline on the scene.
"$offline" "$work/live.lcm" -o "$work/from_log.csv" -q >/dev/null 2>&1
"$offline" "${scene[@]}" -o "$work/direct.csv" -q >/dev/null 2>&1
if ((log_complete)); then
  check "offline run on the lcm-log is byte-identical to the direct run" cmp -s "$work/from_log.csv" "$work/direct.csv"
fi

# The live segments are as accurate as the offline runner's on the same events.
"$eval_tool" --segments "$work/live.lcm" "${scene[@]}" --json "$work/live.json" >/dev/null 2>&1
"$eval_tool" --segments "$work/direct.csv" "${scene[@]}" --json "$work/direct.json" >/dev/null 2>&1
live_f=$(f_at_1_percent "$work/live.json")
offline_f=$(f_at_1_percent "$work/direct.json")
echo "F@1%: live $live_f, offline $offline_f"
if ((kept_up)); then
  check "live F@1% within 0.06 of offline" close_to "$live_f" "$offline_f" 0.06
  check "live F@1% >= 0.75" close_to "$live_f" 0.875 0.125
else
  check "live F@1% >= 0.5 (evldt-lines was starved)" close_to "$live_f" 0.75 0.25
fi

if ((log_complete)); then
  # --- replay: lcm-logplayer feeds the recorded events to a fresh lines service ------------------
  "${logger[@]}" --lcm-url="$replay_url&$logger_buffer" -f -q --channel='LINES_.*|TEST_MARKER' "$work/replay.lcm" &
  replay_logger_pid=$!
  "$lines" --lcm-url "$replay_url" --log-period-s 0 >"$work/replay_lines.out" 2>"$work/replay_lines.err" &
  replay_lines_pid=$!
  "$probe" "$replay_url" cam0 600 >"$work/replay_probe.out" &
  replay_probe_pid=$!
  wait_logger_ready "$replay_url" "$work/replay.lcm" TEST_MARKER
  wait_ready "$work/replay_lines.err" evldt-lines
  wait_until "the probe to subscribe" grep -q '^ready' "$work/replay_probe.out"
  lcm-logplayer --lcm-url="$replay_url" --regexp='EVENTS_.*' "$work/live.lcm"
  wait_until "a replayed segment list including batch $((batches - 1))" probe_heard_batch "$work/replay_probe.out" $((batches - 1))
  replay_lists=$(grep -c '^list' "$work/replay_probe.out")
  wait_until "$replay_lists segment lists in the replay log" log_holds "$replay_url" "$work/replay.lcm" LINES_CAM0 "$replay_lists"
  stops_promptly "$replay_lines_pid"
  stops_promptly "$replay_logger_pid" INT
  kill "$replay_probe_pid"
  cat "$work/replay_lines.out"
  check "replayed lines received every batch" grep -q "batches   $batches received, 0 lost" "$work/replay_lines.out"
  # The log keeps the recording's publish stamps, seconds behind the replay: latency from receipt.
  check "the replay's latency is measured from receipt" grep -q "latency   batch receipt -> segment list" "$work/replay_lines.out"
  check "... and says why" grep -q "measured from receipt for [0-9]* batches: their publish stamps are [0-9.]* ms behind" "$work/replay_lines.out"
  check "the live run's latency is measured from publish" grep -q "latency   batch publish -> segment list" "$work/lines.out"
  "$eval_tool" --segments "$work/replay.lcm" "${scene[@]}" --json "$work/replay.json" >/dev/null 2>&1
  replay_f=$(f_at_1_percent "$work/replay.json")
  echo "F@1%: replayed $replay_f"
  replay_rounds=$(tracking_rounds "$work/replay_lines.out")
  if ((kept_up && ${replay_rounds:-0} * 10 >= 750 * 9)); then
    check "replayed F@1% within 0.06 of the live run" close_to "$replay_f" "$live_f" 0.06
  else
    check "replayed F@1% >= 0.5 (a run was starved)" close_to "$replay_f" 0.75 0.25
  fi

fi

# --- a window without a display is a clear error, not OpenCV's abort -------------------------
env -u DISPLAY -u WAYLAND_DISPLAY "$viz" --lcm-url "$url" >/dev/null 2>"$work/nodisplay.err"
check "evldt-viz without a display exits 1 with a message" test $? -eq 1
check "... that says to run headless" grep -q "no display.*--headless" "$work/nodisplay.err"

# --- lcm-spy decodes every message type -----------------------------------------------------
jar=$build/lcmtypes/evldt_lcmtypes.jar
if [[ -f $jar ]] && command -v javac >/dev/null; then
  javac -d "$work/java" -cp /usr/share/java/lcm.jar "$source_dir/tests/services/LcmSpyDecodeCheck.java"
  java -cp "/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:$jar:$work/java" LcmSpyDecodeCheck "$work/live.lcm" | tee "$work/spy.out"
  check "lcm-spy's type lookup decodes the event, segment and stats messages" \
    grep -q "EVENTS_CAM0 evldt.event_batch_t" "$work/spy.out"
  check "... segment lists" grep -q "LINES_CAM0 evldt.segment_list_t" "$work/spy.out"
  check "... statistics" grep -q "EVLDT_STATS evldt.stats_t" "$work/spy.out"
  check "... the calibrated camera" grep -q "CAMERA_INFO_CAM0 evldt.camera_info_t" "$work/spy.out"
  check "... and the junk does not decode" grep -qP "EVENTS_CAM0 (undecodable|no-type) [1-8]$" "$work/spy.out"
else
  echo "skipped: lcm-spy decoding (no javac or no jar)"
fi

finish
