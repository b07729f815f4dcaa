#!/usr/bin/env bash
# Live inputs end to end, real processes over UDP multicast on loopback (ttl=0): a RAW
# recording fed to evldt-camera in real time in pieces that split its words, as a driver or
# recorder would (pieces of random size are the unit tests' part: tests/sources), through each live path (standard input, a TCP stream, a file followed while it is
# written, libcaer's AEDAT 3.1 network stream, and DV's AEDAT 4.0 network output of a real DVXplorer recording with a server restart
# in the middle: skipped with a message when ../shared is absent) -> evldt-lines -> evldt-viz.
# Every event of the recording must be published, every batch received by evldt-lines and
# evldt-viz, and a segment list must include the last batch.
# Usage: live_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
url="udpm://239.255.76.67:7714?ttl=0"
sim=$build/tools/evldt-sim/evldt-sim

"$sim" --scene boxes-6dof --duration-s 1 --out-dir "$work/rec" --format evt3 --quiet >/dev/null
recording=$work/rec/events.raw
"$camera" "$recording" --lcm-url "$url" --speed 0 -q >"$work/reference.out" 2>"$work/reference.err"
events=$(field "$work/reference.out" "events +")
echo "the recording holds $events events"

# The recording written as a camera driver writes it: in real time (so every service keeps up, a
# sanitizer's too), in pieces of 4099 bytes (odd, so EVT 3.0 words are split between pieces).
pacer=$build/tests/raw_pacer
piece=4099

sensor=(--width 240 --height 180)  # evldt-lines is given the camera's size, as a deployment does
# The servers of the network paths send as fast as they can, which a service under a sanitizer
# cannot keep up with: evldt-lines stores every batch (no latency budget), since what is checked
# here is delivery.
live_path() {  # live_path NAME COMMAND...: the camera on a live input (COMMAND runs it), lines and viz listening
  local name=$1
  shift
  "$lines" --lcm-url "$url" --log-period-s 0 --max-latency-ms 0 "${sensor[@]}" >"$work/$name.lines.out" 2>"$work/$name.lines.err" &
  local lines_pid=$!
  "$viz" --lcm-url "$url" --headless --png-dir "$work/$name.png" --png-period-s 0.5 >"$work/$name.viz.out" 2>"$work/$name.viz.err" &
  local viz_pid=$!
  "$probe" "$url" cam0 120 >"$work/$name.probe.out" &
  local probe_pid=$!
  wait_ready "$work/$name.lines.err" evldt-lines
  wait_ready "$work/$name.viz.err" evldt-viz
  wait_until "the probe to subscribe" grep -q '^ready' "$work/$name.probe.out"
  "$@" >"$work/$name.camera.out" 2>"$work/$name.camera.err"
  check "$name: camera exits 0" test $? -eq 0
  cat "$work/$name.camera.out"
  local batches
  batches=$(field "$work/$name.camera.out" 'batches')
  check "$name: every event of the recording published ($events)" \
    grep -q "events            $events read, $events published" "$work/$name.camera.out"
  check "$name: the camera measured its lag from the sensor" grep -qP "live lag +sensor -> publish: median [0-9.]+ ms, p99 [0-9.]+ ms" "$work/$name.camera.out"
  check "$name: a segment list includes the last batch" \
    wait_until "a segment list including batch $((batches - 1))" probe_heard_batch "$work/$name.probe.out" $((batches - 1))
  stops_promptly "$lines_pid" >/dev/null
  stops_promptly "$viz_pid" >/dev/null
  kill "$probe_pid" 2>/dev/null
  check "$name: evldt-lines received every batch ($batches)" grep -q "batches   $batches received, 0 lost" "$work/$name.lines.out"
  # The viz is a display: when it falls behind (a sanitizer's build at a thousand batches a second)
  # it loses its own batches, counted, by design (docs/services.md: a slow viz never slows the others). What
  # is checked here is that it drew the live stream; every batch reaching evldt-lines is checked above.
  check "$name: evldt-viz received the live stream" grep -qP "received  [1-9][0-9]* batches \\([0-9]+ lost" "$work/$name.viz.out"
}

# 1. Standard input: a driver piping its output.
live_stdin() { "$pacer" "$recording" 1 stdout "$piece" | "$camera" - --lcm-url "$url" -q; }
live_path stdin live_stdin

# 2. A TCP stream.
"$pacer" "$recording" 1 tcp "$work/port" "$piece" &
wait_until "the test server to listen" test -s "$work/port"
live_path tcp "$camera" "tcp://127.0.0.1:$(cat "$work/port")" --lcm-url "$url" -q

# 3. A file followed while a recorder writes it (the run ends 1 s after it stops growing).
: >"$work/growing.raw"
"$pacer" "$recording" 1 append "$work/growing.raw" "$piece" &
live_path follow "$camera" --follow "$work/growing.raw" --follow-idle-s 1 --lcm-url "$url" -q
check "follow: the followed file is the whole recording" cmp -s "$work/growing.raw" "$recording"

# 4. cAER / libcaer's AEDAT 3.1 network output of the same recording (it names no sensor size).
rm -f "$work/aedat31_port"
"$build/tests/aedat31_stream_server" "$recording" "$work/aedat31_port" &
wait_until "the AEDAT 3.1 test server to listen" test -s "$work/aedat31_port"
live_path aedat31 "$camera" "tcp://127.0.0.1:$(cat "$work/aedat31_port")" --width 240 --height 180 --lcm-url "$url" -q

# 5. DV's AEDAT 4.0 network output, from a real DVXplorer recording; the server goes away in the
#    middle and comes back (--reconnect), and every event must arrive once.
dv_recording=$source_dir/../shared/real/dvxplorer_person.aedat4
if [[ -f $dv_recording ]]; then
  "$camera" "$dv_recording" --lcm-url "$url" --speed 0 -q >"$work/dv_reference.out" 2>"$work/dv_reference.err"
  events=$(field "$work/dv_reference.out" "events +")
  sensor=(--width 320 --height 240)
  rm -f "$work/dv_port"
  "$build/tests/dv_stream_server" "$dv_recording" "$work/dv_port" split &
  dv_server_pid=$!
  wait_until "the DV test server to listen" test -s "$work/dv_port"
  # The camera reconnects until stopped: stop it once the server has served both connections.
  live_dv() {
    "$camera" "tcp://127.0.0.1:$(cat "$work/dv_port")" --format aedat4 --reconnect --lcm-url "$url" -q &
    local camera_pid=$!
    wait "$dv_server_pid"
    sleep 1
    kill -INT "$camera_pid"
    wait "$camera_pid"
  }
  live_path dv live_dv
  check "dv: the camera connected again after the server went away" grep -qP "live input +[1-9][0-9]* reconnects" "$work/dv.camera.out"
else
  echo "skipped: DV network stream ($dv_recording is absent: ../shared is not beside the project)"
fi

finish
