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
# The hosts are really apart: what host 2 sends with ttl=0 stays on host 2, with ttl=1 it reaches host 3.
heard_from_host2() {  # heard_from_host2 TTL: messages host 3 hears when host 2 publishes 10
  local ttl_url=${url%ttl=1}ttl=$1
  "${h3[@]}" "$probe" "$ttl_url" cam0 1.5 >"$work/ttl$1.out" &
  local listener=$!
  sleep 0.5
  "${h2[@]}" "$junk" "$ttl_url" LINES_CAM0 10
  wait "$listener"
  grep -c '^invalid' "$work/ttl$1.out"
}
check "ttl=0 traffic of host 2 does not reach host 3" test "$(heard_from_host2 0)" -eq 0
check "ttl=1 traffic of host 2 reaches host 3 across the bridge" test "$(heard_from_host2 1)" -eq 10

"${h3[@]}" "$probe" "$url" cam0 5 >"$work/probe.out" &
probe_pid=$!
"${h3[@]}" lcm-logger --lcm-url="$url" -f -q "$work/far.lcm" &
logger_pid=$!
"${h3[@]}" "$viz" --lcm-url "$url" --headless --png-dir "$work/png" --png-period-s 0.5 >"$work/viz.out" 2>"$work/viz.err" &
viz_pid=$!
"${h2[@]}" "$lines" --lcm-url "$url" --log-period-s 0 >"$work/lines.out" 2>"$work/lines.err" &
lines_pid=$!
sleep 0.7
"${h1[@]}" "$camera" --lcm-url "$url" --scene boxes-6dof --duration-s 2 -q >"$work/camera.out" 2>"$work/camera.err"
check "camera on host 1 exits 0" test $? -eq 0
sleep 0.3
check "evldt-lines on host 2 stops within 1 s of SIGTERM" stops_within_a_second "$lines_pid"
check "evldt-viz on host 3 stops within 1 s of SIGTERM" stops_within_a_second "$viz_pid"
stops_within_a_second "$logger_pid" INT
wait "$probe_pid"
cat "$work/camera.out" "$work/lines.out" "$work/viz.out"

batches=$(field "$work/camera.out" 'batches')
check "host 2 received every batch of host 1 ($batches)" grep -q "batches   $batches received, 0 lost" "$work/lines.out"
lists=$(grep -c '^list' "$work/probe.out")
with_segments=$(awk '$1 == "list" && $6 > 0' "$work/probe.out" | wc -l)
echo "host 3 heard $lists segment lists, $with_segments with segments"
check "segments from host 2 arrive on host 3" test "$with_segments" -gt 50
check "statistics from host 2 arrive on host 3" grep -q '^stats' "$work/probe.out"
check "evldt-viz on host 3 drew the events of host 1 and the segments of host 2" \
  grep -qP "received  $batches batches \(0 lost, 0 invalid\), [1-9][0-9]* segment lists \(0 invalid\)" "$work/viz.out"
check "lcm-logger on host 3 recorded the far traffic" test -s "$work/far.lcm"

finish
