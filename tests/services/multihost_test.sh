#!/usr/bin/env bash
# Three hosts on one machine: network namespaces joined by veth pairs to a bridge in a fourth
# (the "switch"), all made and removed by this test. The camera runs on host 1, evldt-lines on
# host 2, evldt-viz, lcm-logger and a segment subscriber on host 3; LCM multicast crosses the bridge
# with ttl=1. Checks that segments computed on host 2 from host 1's events arrive on host 3.
# Exits 77 (ctest: skipped) where this machine does not allow creating namespaces.
# Usage: multihost_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
url="udpm://239.255.76.67:7714?ttl=1"
tag=evldt$$
switch=${tag}sw
hosts=(${tag}h1 ${tag}h2 ${tag}h3)

if ! ip netns add "$switch" 2>"$work/netns.err"; then
  echo "SKIPPED: cannot create network namespaces here ($(cat "$work/netns.err")); needs root or CAP_SYS_ADMIN"
  exit 77
fi
cleanup_hooks+=("for ns in $switch ${hosts[*]}; do ip netns del \$ns 2>/dev/null; done")
set -e
ip -n "$switch" link add br0 type bridge
# Flood multicast to every port: no IGMP querier runs on this private bridge.
ip -n "$switch" link set br0 type bridge mcast_snooping 0
ip -n "$switch" link set br0 up
for i in 0 1 2; do
  host=${hosts[$i]}
  ip netns add "$host"
  ip link add "${tag}v$i" netns "$host" type veth peer name "port$i" netns "$switch"
  ip -n "$host" link set "${tag}v$i" name eth0
  ip -n "$host" addr add "10.77.0.$((i + 1))/24" dev eth0
  ip -n "$host" link set eth0 up
  ip -n "$host" link set lo up
  ip -n "$host" route add 224.0.0.0/4 dev eth0
  ip -n "$switch" link set "port$i" master br0
  ip -n "$switch" link set "port$i" up
done
set +e
# `ip netns exec` execs the command, so $! of a background one is the command itself.
h1=(ip netns exec "${hosts[0]}")
h2=(ip netns exec "${hosts[1]}")
h3=(ip netns exec "${hosts[2]}")
# The hosts are really apart: what host 2 sends with ttl=0 stays on host 2, with ttl=1 it reaches
# host 3. Host 2 sends 10 messages on LINES_CAM0 with ttl=0, then 10 on EVLDT_STATS with ttl=1:
# once host 3 has heard the second ten, the first would have arrived before them.
"${h3[@]}" "$probe" "$url" cam0 600 >"$work/ttl.out" &
ttl_probe_pid=$!
wait_until "the probe on host 3 to subscribe" grep -q '^ready' "$work/ttl.out"
"${h2[@]}" "$junk" "${url%ttl=1}ttl=0" LINES_CAM0 10
"${h2[@]}" "$junk" "$url" EVLDT_STATS 10
check "ttl=1 traffic of host 2 reaches host 3 across the bridge" \
  wait_until "10 messages of host 2 on host 3" awk '$1 == "invalid" && $3 == "EVLDT_STATS" { n++ } END { exit !(n >= 10) }' "$work/ttl.out"
kill "$ttl_probe_pid"
check "ttl=0 traffic of host 2 does not reach host 3" test "$(grep -c '^invalid [0-9]* LINES_CAM0' "$work/ttl.out")" -eq 0

"${h3[@]}" "$probe" "$url" cam0 600 >"$work/probe.out" &
probe_pid=$!
"${h3[@]}" "${logger[@]}" --lcm-url="$url&$logger_buffer" -f -q "$work/far.lcm" &
logger_pid=$!
"${h3[@]}" "$viz" --lcm-url "$url" --headless --png-dir "$work/png" --png-period-s 0.5 >"$work/viz.out" 2>"$work/viz.err" &
viz_pid=$!
"${h2[@]}" "$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines.out" 2>"$work/lines.err" &
lines_pid=$!
wait_until "the probe on host 3 to subscribe" grep -q '^ready' "$work/probe.out"
wait_ready "$work/viz.err" evldt-viz
wait_ready "$work/lines.err" evldt-lines
logger_ready() { "${h2[@]}" "$junk" "$url" TEST_MARKER 1 && sleep 0.1 && test "$("$log_count" "$work/far.lcm" TEST_MARKER)" -gt 0; }
wait_until "lcm-logger on host 3 to record" logger_ready
"${h1[@]}" "$camera" --lcm-url "$url" --scene boxes-6dof --duration-s 2 -q >"$work/camera.out" 2>"$work/camera.err"
check "camera on host 1 exits 0" test $? -eq 0
batches=$(field "$work/camera.out" 'batches')
check "host 3 heard a segment list of host 2 that includes host 1's last batch" \
  wait_until "a list including batch $((batches - 1))" probe_heard_batch "$work/probe.out" $((batches - 1))
far_log_holds() { "${h2[@]}" "$junk" "$url" TEST_MARKER 1 && test "$("$log_count" "$work/far.lcm" EVENTS_CAM0)" -ge "$batches"; }
far_log_complete() {
  wait_until "$batches batches in the far log" far_log_holds && return 0
  echo "  the far log holds $("$log_count" "$work/far.lcm" EVENTS_CAM0) of $batches batches"
  return 1
}
# The stock lcm-logger drops past a 30-message queue when it waits for a core; that every batch
# reached host 3 is checked on evldt-viz there, below.
if far_log_complete; then
  echo "ok: lcm-logger on host 3 recorded every batch of host 1"
else
  echo "note: lcm-logger on host 3 missed batches on a starved machine"
fi
check "evldt-lines on host 2 stops promptly at SIGTERM" stops_promptly "$lines_pid"
check "evldt-viz on host 3 stops promptly at SIGTERM" stops_promptly "$viz_pid"
stops_promptly "$logger_pid" INT
kill "$probe_pid"
cat "$work/camera.out" "$work/lines.out" "$work/viz.out"

check "host 2 received every batch of host 1 ($batches)" grep -q "batches   $batches received, 0 lost" "$work/lines.out"
lists=$(grep -c '^list' "$work/probe.out")
with_segments=$(awk '$1 == "list" && $7 > 0' "$work/probe.out" | wc -l)
echo "host 3 heard $lists segment lists, $with_segments with segments"
check "segments from host 2 arrive on host 3" test "$with_segments" -gt 50
check "statistics from host 2 arrive on host 3" grep -q '^stats' "$work/probe.out"
check "evldt-viz on host 3 drew the events of host 1 and the segments of host 2" \
  grep -qP "received  $batches batches \(0 lost, 0 invalid\), [1-9][0-9]* segment lists \(0 invalid\)" "$work/viz.out"

finish
