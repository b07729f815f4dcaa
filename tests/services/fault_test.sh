#!/usr/bin/env bash
# Faults with the real processes over UDP multicast on loopback (ttl=0):
#  1. evldt-lines killed with SIGKILL mid-stream and started again: the camera keeps publishing, the
#     new process publishes segments within 1 s of its start, and no line id of the first process
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
"$probe" "$url" cam0 8 >"$work/probe1.out" &
probe_pid=$!
"$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines1.out" 2>"$work/lines1.err" &
lines1_pid=$!
sleep 0.5
"$camera" --lcm-url "$url" --scene boxes-6dof --duration-s 5 -q >"$work/camera1.out" 2>"$work/camera1.err" &
camera_pid=$!
sleep 2
kill -9 "$lines1_pid"
sleep 0.2
restarted_at=$(now_us)
"$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines2.out" 2>"$work/lines2.err" &
lines2_pid=$!
wait "$camera_pid"
check "camera published the whole scene through the restart" test $? -eq 0
cat "$work/camera1.out"
check "... with no publish failure" grep -q " 0 publish failures" "$work/camera1.out"
sleep 0.3
check "the restarted evldt-lines stops within 1 s of SIGTERM" stops_within_a_second "$lines2_pid"
wait "$probe_pid"
cat "$work/lines2.out"

epochs=($(awk '$1 == "list" { print $3 }' "$work/probe1.out" | uniq))
check "lists came from two processes (epochs ${epochs[*]})" test "${#epochs[@]}" -eq 2
first_segments_us=$(awk -v e="${epochs[1]:-0}" '$1 == "list" && $3 == e && $6 > 0 { print $2; exit }' "$work/probe1.out")
resumed_ms=$(( (${first_segments_us:-99999999999999999} - restarted_at) / 1000 ))
echo "restarted process: first segments $resumed_ms ms after its start"
check "the restarted process publishes segments within 1 s of its start" test "$resumed_ms" -lt 1000
awk -v e="${epochs[0]:-0}" '$1 == "list" && $3 == e { for (i = 7; i <= NF; ++i) print $i }' "$work/probe1.out" | sort -u >"$work/ids1"
awk -v e="${epochs[1]:-0}" '$1 == "list" && $3 == e { for (i = 7; i <= NF; ++i) print $i }' "$work/probe1.out" | sort -u >"$work/ids2"
echo "line ids: $(wc -l <"$work/ids1") before the kill, $(wc -l <"$work/ids2") after the restart"
check "both processes created lines" test -s "$work/ids1" -a -s "$work/ids2"
check "no line id repeats across the restart" test -z "$(comm -12 "$work/ids1" "$work/ids2")"
check "the restarted process lost no batch (it begins counting at its first)" grep -q " received, 0 lost" "$work/lines2.out"

# --- 2 and 3. datagram loss, and a stalled subscriber -----------------------------------------
duration_s=4
lcm-logger --lcm-url="$url" -f -q --channel='LINES_CAM0' "$work/lossy.lcm" &
logger_pid=$!
"$relay" "$url" EVENTS_RAW EVENTS_CAM0 20 2 >"$work/relay.out" &
relay_pid=$!
"$probe" "$url" cam0 $((duration_s + 2)) >"$work/probe2.out" &
probe_pid=$!
"$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines3.out" 2>"$work/lines3.err" &
lines_pid=$!
"$viz" --lcm-url "$url" --headless --png-dir "$work/png" --png-period-s 0.5 >"$work/viz.out" 2>"$work/viz.err" &
viz_pid=$!
sleep 0.5
"$camera" --lcm-url "$url" --camera raw --scene boxes-6dof --duration-s "$duration_s" -q >"$work/camera2.out" 2>"$work/camera2.err" &
camera_pid=$!
sleep 1
kill -STOP "$viz_pid"
stall_from=$(now_us)
sleep 2
stall_to=$(now_us)
kill -CONT "$viz_pid"
wait "$camera_pid" "$relay_pid"  # the relay has forwarded the whole stream
sleep 0.3
stops_within_a_second "$lines_pid"
stops_within_a_second "$viz_pid"
wait "$probe_pid"
stops_within_a_second "$logger_pid" INT
cat "$work/relay.out" "$work/lines3.out" "$work/viz.out"

dropped=$(field "$work/relay.out" 'dropped')
lost=$(grep -oP 'received, \K[0-9]+(?= lost)' "$work/lines3.out")
check "evldt-lines counted every dropped batch as lost ($lost of $dropped)" test "${lost:-x}" = "$dropped" -a "$dropped" -gt 0
stats_lost=$(awk '$1 == "stats" { v = $5 } END { print v + 0 }' "$work/probe2.out")
check "its statistics messages report the loss ($stats_lost)" test "$stats_lost" -gt 0
check "every segment list heard was valid" test "$(grep -c '^invalid' "$work/probe2.out")" -eq 0
lists_in_stall=$(awk -v a="$stall_from" -v b="$stall_to" '$1 == "list" && $2 >= a && $2 < b' "$work/probe2.out" | wc -l)
echo "segment lists heard while evldt-viz was stopped: $lists_in_stall in 2 s (publish rate 100 Hz)"
check "a stopped subscriber does not slow evldt-lines (>= 180 lists in the 2 s)" test "$lists_in_stall" -ge 180
"$eval_tool" --segments "$work/lossy.lcm" --scene boxes-6dof --duration-s "$duration_s" --json "$work/lossy.json" >/dev/null 2>&1
lossy_f=$(f_at_1_percent "$work/lossy.json")
echo "F@1% with every 20th batch lost: $lossy_f"
check "segments stay accurate under 5% batch loss (F@1% >= 0.7)" close_to "$lossy_f" 0.85 0.15

finish
