#!/usr/bin/env bash
# Faults with the real processes over UDP multicast on loopback (ttl=0):
#  1. evldt-lines killed with SIGKILL mid-stream and started again: the camera keeps publishing, the
#     new process publishes segments (how soon is printed), and no line id of the first process
#     comes back in the second.
#  2. Datagram loss (a relay dropping every 20th event batch, as this kernel has no netem): every
#     lost batch is counted by evldt-lines, in its summary and its statistics, and the segments stay
#     valid and accurate.
#  3. A stalled subscriber (evldt-viz stopped with SIGSTOP for 2 s) does not slow evldt-lines.
# Usage: fault_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
url="udpm://239.255.76.67:7713?ttl=0"
now_us() { date +%s%6N; }

# --- 1. kill -9 and restart ---------------------------------------------------------------------
"$probe" "$url" cam0 600 >"$work/probe1.out" &
probe_pid=$!
"$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines1.out" 2>"$work/lines1.err" &
lines1_pid=$!
wait_ready "$work/lines1.err" evldt-lines
wait_until "the probe to subscribe" grep -q '^ready' "$work/probe1.out"
"$camera" --lcm-url "$url" --scene boxes-6dof --duration-s 5 -q >"$work/camera1.out" 2>"$work/camera1.err" &
camera_pid=$!
# Mid-stream: once the first process has published 50 lists with segments.
wait_until "50 segment lists with segments from the first evldt-lines" \
  awk '$1 == "list" && $7 > 0 { n++ } END { exit !(n >= 50) }' "$work/probe1.out"
kill -9 "$lines1_pid"
restarted_at=$(now_us)
"$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines2.out" 2>"$work/lines2.err" &
lines2_pid=$!
wait "$camera_pid"
check "camera published the whole scene through the restart" test $? -eq 0
cat "$work/camera1.out"
check "... with no publish failure" grep -q " 0 publish failures" "$work/camera1.out"
batches=$(field "$work/camera1.out" 'batches')
check "the restarted evldt-lines published a segment list that includes the last batch" \
  wait_until "a list of the second process including batch $((batches - 1))" \
  probe_heard_batch "$work/probe1.out" $((batches - 1)) "$(awk '$1 == "list" { e = $3 } END { print e }' "$work/probe1.out")"
check "the restarted evldt-lines stops promptly at SIGTERM" stops_promptly "$lines2_pid"
kill "$probe_pid"
cat "$work/lines2.out"

epochs=($(awk '$1 == "list" { print $3 }' "$work/probe1.out" | uniq))
check "lists came from two processes (epochs ${epochs[*]})" test "${#epochs[@]}" -eq 2
first_segments_us=$(awk -v e="${epochs[1]:-0}" '$1 == "list" && $3 == e && $7 > 0 { print $2; exit }' "$work/probe1.out")
# How soon is printed, not judged: a loaded machine starts a process slowly.
echo "restarted process: first segments $(( (${first_segments_us:-0} - restarted_at) / 1000 )) ms after its start"
check "the restarted process published segments" test -n "$first_segments_us"
awk -v e="${epochs[0]:-0}" '$1 == "list" && $3 == e { for (i = 8; i <= NF; ++i) print $i }' "$work/probe1.out" | sort -u >"$work/ids1"
awk -v e="${epochs[1]:-0}" '$1 == "list" && $3 == e { for (i = 8; i <= NF; ++i) print $i }' "$work/probe1.out" | sort -u >"$work/ids2"
echo "line ids: $(wc -l <"$work/ids1") before the kill, $(wc -l <"$work/ids2") after the restart"
check "both processes created lines" test -s "$work/ids1" -a -s "$work/ids2"
check "no line id repeats across the restart" test -z "$(comm -12 "$work/ids1" "$work/ids2")"
check "the restarted process lost no batch (it begins counting at its first)" grep -q " received, 0 lost" "$work/lines2.out"

# --- 2 and 3. datagram loss, and a stalled subscriber -----------------------------------------
duration_s=4
"${logger[@]}" --lcm-url="$url&$logger_buffer" -f -q --channel='LINES_CAM0|TEST_MARKER' "$work/lossy.lcm" &
logger_pid=$!
# The relay receives like the services (8 MiB buffer): a batch it missed would count as lost twice over.
"$relay" "$url&$logger_buffer" EVENTS_RAW EVENTS_CAM0 20 2 >"$work/relay.out" &
relay_pid=$!
"$probe" "$url" cam0 600 >"$work/probe2.out" &
probe_pid=$!
"$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines3.out" 2>"$work/lines3.err" &
lines_pid=$!
"$viz" --lcm-url "$url" --headless --png-dir "$work/png" --png-period-s 0.5 >"$work/viz.out" 2>"$work/viz.err" &
viz_pid=$!
wait_logger_ready "$url" "$work/lossy.lcm" TEST_MARKER
wait_ready "$work/lines3.err" evldt-lines
wait_ready "$work/viz.err" evldt-viz
wait_until "the probe to subscribe" grep -q '^ready' "$work/probe2.out"
wait_until "the relay to subscribe" grep -q '^ready' "$work/relay.out"
"$camera" --lcm-url "$url" --camera raw --scene boxes-6dof --duration-s "$duration_s" -q >"$work/camera2.out" 2>"$work/camera2.err" &
camera_pid=$!
wait_until "evldt-lines to publish segments" awk '$1 == "list" && $7 > 0 { found = 1 } END { exit !found }' "$work/probe2.out"
kill -STOP "$viz_pid"
stall_from=$(now_us)
sleep 2  # the fault itself: the viz is stopped for 2 s
stall_to=$(now_us)
kill -CONT "$viz_pid"
wait "$camera_pid" "$relay_pid"  # the relay has forwarded the whole stream (it stops after 2 s of silence)
batches=$(field "$work/camera2.out" 'batches')
# The relay drops the middle batch of every 20, so the stream's last batch is delivered.
wait_until "a segment list including batch $((batches - 1))" probe_heard_batch "$work/probe2.out" $((batches - 1))
check "evldt-lines stops promptly at SIGTERM" stops_promptly "$lines_pid"
check "evldt-viz stops promptly at SIGTERM" stops_promptly "$viz_pid"
kill "$probe_pid"
lists_heard=$(grep -c '^list' "$work/probe2.out")
wait_until "$lists_heard segment lists in the log" log_holds "$url" "$work/lossy.lcm" LINES_CAM0 "$lists_heard"
stops_promptly "$logger_pid" INT
cat "$work/relay.out" "$work/lines3.out" "$work/viz.out"

dropped=$(field "$work/relay.out" 'dropped')
lost=$(grep -oP 'received, \K[0-9]+(?= lost)' "$work/lines3.out")
check "evldt-lines counted every dropped batch as lost ($lost of $dropped)" test "${lost:-x}" = "$dropped" -a "$dropped" -gt 0
stats_lost=$(awk '$1 == "stats" && $3 == "evldt-lines" { v = $6 } END { print v + 0 }' "$work/probe2.out")
check "its statistics messages report the loss ($stats_lost)" test "$stats_lost" -gt 0
check "every segment list heard was valid" test "$(grep -c '^invalid' "$work/probe2.out")" -eq 0
# Not slowed: evldt-lines published as many lists a second while the viz was stopped as over the
# rest of its run (a rate against its own rate, so a slow machine is not a failure).
read -r in_stall rate_in_stall rate_outside < <(awk -v a="$stall_from" -v b="$stall_to" '
  $1 == "list" { if (first == 0) first = $2; last = $2; if ($2 >= a && $2 < b) n_in++; else n_out++ }
  END { out_s = (last - first - (b - a)) / 1e6; printf "%d %.1f %.1f\n", n_in, n_in / ((b - a) / 1e6), n_out / out_s }' "$work/probe2.out")
echo "segment lists heard while evldt-viz was stopped: $in_stall ($rate_in_stall/s; $rate_outside/s outside the stall)"
check "a stopped subscriber does not slow evldt-lines (list rate in the stall >= 0.8x the rest)" \
  awk -v a="$rate_in_stall" -v b="$rate_outside" 'BEGIN { exit !(a >= 0.8 * b && a > 0) }'
"$eval_tool" --segments "$work/lossy.lcm" --scene boxes-6dof --duration-s "$duration_s" --json "$work/lossy.json" >/dev/null 2>&1
lossy_f=$(f_at_1_percent "$work/lossy.json")
echo "F@1% with every 20th batch lost: $lossy_f"
check "segments stay accurate under 5% batch loss (F@1% >= 0.7)" close_to "$lossy_f" 0.85 0.15

finish
