#!/usr/bin/env bash
# Bounded latency with the real processes over UDP multicast on loopback (ttl=0):
#  1. A run well within the machine's means sheds no batch and thins few; its receiving and storing
#     threads run 10 nice steps above its rounds, LCM's socket reader real-time, and the camera 10
#     steps above normal (where the test may raise them: as root); waiting, before the stream and
#     after it, costs no CPU.
#  2. A consumer slowed on purpose (evldt-lines stopped with SIGSTOP for 300 ms, twice) sheds the
#     batches that queued past its latency budget (thinning those below it), counts them apart from
#     losses (summary and statistics messages), slows its whole lines meanwhile, loses none, and keeps
#     the median latency of what it stored within the budget.
# Usage: overload_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
url="udpm://239.255.76.67:7714?ttl=0"
budget_ms=20
# The unhurried run's budget: a sanitizer build runs the service several times slower (ThreadSanitizer
# 5-15x), beside other tests, so 20 ms is not within its means there; it must still shed nothing
# systematically (a wrong clock estimate would shed whatever the budget). Under ThreadSanitizer the
# first second after the first batch queues up to some 200 ms (p99 137-200 ms in failing runs, 16-23
# ms after it; 100 ms failed 7 of 18 runs on 2026-12-05, the code of then and before alike).
idle_budget_ms=$budget_ms
grep -q '^EVLDT_SANITIZE:STRING=.' "$build/CMakeCache.txt" 2>/dev/null && idle_budget_ms=400

run_camera() {  # run_camera OUT: boxes-6dof in real time, 3 s
  "$camera" --lcm-url "$url" --scene boxes-6dof --duration-s 3 -q >"$1" 2>&1
}

# --- 1. within means ----------------------------------------------------------------------------
"$lines" --lcm-url "$url" --log-period-s 0 --max-latency-ms "$idle_budget_ms" >"$work/idle.out" 2>"$work/idle.err" &
lines_pid=$!
wait_ready "$work/idle.err" evldt-lines
# Waiting costs no CPU: a busy loop costs a core. Before the first batch (no engine yet) here, and
# after the stream below.
cpu_ticks() { awk '{ print $14 + $15 }' "/proc/$1/stat"; }
mostly_idle() {  # mostly_idle PID: the process used under a fifth of a core over 2 s
  local before after
  before=$(cpu_ticks "$1")
  sleep 2
  after=$(cpu_ticks "$1")
  echo "  CPU over 2 s: $(((after - before) * 100 / ($(getconf CLK_TCK) * 2)))% of a core"
  ((after - before < $(getconf CLK_TCK) * 2 / 5))
}
check "evldt-lines waiting for its first batch is idle" mostly_idle "$lines_pid"
run_camera "$work/camera1.out" &
camera_pid=$!
# The engine's threads start with the first batch. Each thread's id, name and nice value from its
# stat line (one awk for all, so polling disturbs little; names have no spaces here); the
# receiving thread is the main one.
thread_nice() { awk '{ gsub(/[()]/, "", $2); print $1, $2, $19, $41 }' /proc/"$lines_pid"/task/*/stat; }
tracking_started() { thread_nice | grep -q ' evldt-track '; }
wait_until "evldt-lines's tracking thread" tracking_started
threads=$(thread_nice)
echo "$threads"
if [[ $(id -u) == 0 ]]; then
  check "the receiving thread runs 10 nice steps above the tracking loop" \
    awk -v pid="$lines_pid" '$1 == pid { r = $3 } $2 == "evldt-track" { t = $3 } END { exit !(r != "" && t != "" && t - r == 10) }' <<<"$threads"
  check "the storing thread runs 10 nice steps above the tracking loop" \
    awk '$2 == "evldt-store" { s = $3 } $2 == "evldt-track" { t = $3 } END { exit !(s != "" && t != "" && t - s == 10) }' <<<"$threads"
  # Policy 1 is SCHED_FIFO: LCM's thread reading the socket (and, in a ThreadSanitizer build, the
  # sanitizer's own thread, which starts with it); never storage or the rounds.
  check "LCM's socket reader runs real-time" \
    awk '$4 == 1 { n++; if ($2 != "evldt-lines") bad++ } END { exit !(n >= 1 && n <= 2 && bad == 0) }' <<<"$threads"
  check "the camera runs 10 nice steps above normal" \
    awk '{ exit !($19 == -10) }' /proc/"$(pgrep -n -f "evldt-camera --lcm-url ${url%%\?*}")"/stat
else
  echo "skipped the priority check: not root, so evldt-lines may not raise its receiving thread"
fi
wait "$camera_pid"
batches=$(field "$work/camera1.out" 'batches')
sleep 0.5  # the last batches and lists
check "evldt-lines after its stream ended is idle" mostly_idle "$lines_pid"
kill -INT "$lines_pid"
wait "$lines_pid"
cat "$work/idle.out"
check "an unhurried run sheds no batch (budget $idle_budget_ms ms)" grep -qP "not stored: 0 batches shed whole" "$work/idle.out"
# Batches that queued past the budget are thinned: a loaded machine (the suite runs tests side by
# side) may delay a few; a wrong clock estimate would thin every batch (half of its events or more).
idle_events=$(field "$work/idle.out" 'events +')
idle_thinned=$(field "$work/idle.out" 'shed')
check "... and thins at most a few ($idle_thinned of $idle_events events not stored)" \
  awk -v s="${idle_thinned:-1e9}" -v n="${idle_events:-0}" 'BEGIN { exit !(s <= 0.05 * n) }'
check "... and loses nothing" grep -qP "batches +$batches received, 0 lost" "$work/idle.out"
# Each batch thinned slows the whole lines for a second after it, so a few thinned batches cost a
# few slow lists; a wrong clock estimate would slow them all.
idle_whole_lists=$(field "$work/idle.out" "segment lists published,")
idle_slow_lists=$(grep -oP 'whole-line lists \(\K[0-9]+(?= at [0-9]+ Hz while shedding)' "$work/idle.out" || echo 1e9)
check "... and keeps its whole lines at their full rate but after a thinned batch ($idle_slow_lists slowed)" \
  awk -v slow="$idle_slow_lists" -v thinned="${idle_thinned:-1e9}" -v lists="${idle_whole_lists:-0}" \
    'BEGIN { exit !(thinned > 0 ? slow <= 0.25 * lists : slow == 0) }'

# --- 2. slowed on purpose -----------------------------------------------------------------------
"$probe" "$url" cam0 60 >"$work/probe.out" &
"$lines" --lcm-url "$url" --log-period-s 0 --max-latency-ms "$budget_ms" >"$work/slow.out" 2>"$work/slow.err" &
lines_pid=$!
wait_ready "$work/slow.err" evldt-lines
wait_until "the probe to subscribe" grep -q '^ready' "$work/probe.out"
run_camera "$work/camera2.out" &
camera_pid=$!
# The stalls start once batches flow (the tracking thread starts with the first): on a busy machine
# the camera can take over a second to start, and stalls before it would stall nothing.
wait_until "evldt-lines's tracking thread" tracking_started
for _ in 1 2; do
  sleep 0.5
  kill -STOP "$lines_pid"
  sleep 0.3
  kill -CONT "$lines_pid"
done
wait "$camera_pid"
batches=$(field "$work/camera2.out" 'batches')
sleep 1.5  # a statistics message after the last batch
kill -INT "$lines_pid"
wait "$lines_pid"
cat "$work/slow.out"
shed=$(field "$work/slow.out" 'not stored:')
p99=$(grep -oP 'p99 \K[0-9.]+' "$work/slow.out" | head -1)
check "the stalled evldt-lines shed batches that queued past ${budget_ms} ms ($shed)" test "${shed:-0}" -gt 0
check "... counted apart from losses: none lost" grep -qP "batches +$batches received, 0 lost" "$work/slow.out"
loaded=$(grep -oP 'whole-line lists \(\K[0-9]+(?= at [0-9]+ Hz while shedding)' "$work/slow.out" || true)
check "... and slowed its whole lines while it shed, so the rounds get the CPU first ($loaded lists)" test "${loaded:-0}" -gt 0
check "... in its statistics messages too" \
  awk -v n="$shed" '$1 == "stats" && $3 == "evldt-lines" { v = $9 } END { exit !(v > 0 && v <= n) }' "$work/probe.out"
# Shed, what is stored waits at most the budget plus a round and a list; the few batches stored just
# before a stall wait it out. The median is asserted; the p99 is printed (19.6 ms in quiet runs, but
# about 300 ms in runs on a busier machine, where about half the stalled batches were stored: not
# explained yet, see the issue note).
median=$(grep -oP 'median \K[0-9.]+' "$work/slow.out" | head -1)
echo "latency of what it stored: median $median ms, p99 $p99 ms"
check "the latency of what it stored stays within the budget (median $median ms < $budget_ms ms)" \
  awk -v m="${median:-1e9}" -v b="$budget_ms" 'BEGIN { exit !(m < b) }'

echo "$failures failure(s)"
exit $((failures > 0))
