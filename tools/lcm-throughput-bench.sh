#!/usr/bin/env bash
# End-to-end LCM throughput on loopback: evldt-camera replays a simulated recording in a loop at
# rising speed factors into evldt-lines for SECONDS each; reports per speed the event rate, batches
# lost, CPU use of each process, bytes per event on the wire and the latency from batch publish to
# the segment list that includes it (median / p99, and p99 once settled: from 1 s after the first
# batch, past the start's cold caches), the batches shed over evldt-lines' latency
# budget and those thinned below it (with the share of events not stored), and the live F@1% (lcm-logger records the segment lists, evldt-eval scores them against
# the scene's ground truth over the event time the run covered: the recording is made as long as
# the longest run covers, up to --scene-s, so the start-up is a small part of the score); then
# the highest rate held: zero lost batches and p99 latency under --max-p99-ms (LCM queues up to
# 4096 batches, so a lines service that falls behind shows as latency before it shows as loss).
# --repeats N runs the speeds N times over, in turn (so a drift of the machine touches every speed
# alike), and ends with the median of each figure per speed: one run of a busy scene varies by
# tens of percent here.
# Usage: tools/lcm-throughput-bench.sh [--scene NAME] [--scene-s S] [--seconds S] [--publish-hz HZ] [--speeds "1 2 4"]
#                                      [--repeats N] [--max-p99-ms MS] [--json FILE] [--build DIR] [--no-f]
#                                      [--lines-arg ARG]...  (passed to evldt-lines, e.g. --no-whole-lines)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build/release
scene=monitor-hd
scene_s_max=3
seconds=10
publish_hz=1000
speeds="0.05 0.1 0.25 0.5 1 1.25"
max_p99_ms=5
repeats=1
json=
lines_args=()
score=true
while (($#)); do
  case $1 in
    --scene) scene=$2; shift 2 ;;
    --scene-s) scene_s_max=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --publish-hz) publish_hz=$2; shift 2 ;;
    --speeds) speeds=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --max-p99-ms) max_p99_ms=$2; shift 2 ;;
    --json) json=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --lines-arg) lines_args+=("$2"); shift 2 ;;
    --no-f) score=false; shift ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "lcm-throughput-bench.sh: unknown argument $1 (see --help)" >&2; exit 1 ;;
  esac
done
[[ $repeats =~ ^[1-9][0-9]*$ ]] || { echo "lcm-throughput-bench.sh: --repeats takes a positive whole number, got '$repeats'" >&2; exit 1; }
camera=$build/services/evldt-camera/evldt-camera
lines=$build/services/evldt-lines/evldt-lines
sim=$build/tools/evldt-sim/evldt-sim
eval_tool=$build/tools/evldt-eval/evldt-eval
for program in "$camera" "$lines" "$sim" "$eval_tool"; do
  [[ -x $program ]] || { echo "lcm-throughput-bench.sh: $program missing: build first" >&2; exit 1; }
done
"$root/deploy/multicast-route.sh"
# A port of its own, so a running system is not disturbed.
url="udpm://239.255.76.67:7719?ttl=0"
work=$(mktemp -d)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -9 "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

# Event time of the longest run, at most --scene-s: the camera loops the recording beyond it.
scene_s=$(awk -v s="$seconds" -v m="$scene_s_max" -v speeds="$speeds" \
  'BEGIN { n = split(speeds, v, " "); top = 0; for (i = 1; i <= n; i++) if (v[i] > top) top = v[i]; d = top * s; print (d < m) ? d : m }')
"$sim" --scene "$scene" --duration-s "$scene_s" --out-dir "$work/rec" --format evt3 --quiet >/dev/null
recording=$work/rec/events.raw
# The sensor size, given to evldt-lines as a deployment gives its camera's (config/WxH.toml), so
# that it builds its lattice and filters at start, not while the first batches queue.
geometry=$(head -c 512 "$recording" | grep -aoP '^% geometry \K[0-9]+x[0-9]+' || true)
[[ -n $geometry ]] || { echo "lcm-throughput-bench.sh: no sensor geometry in $recording" >&2; exit 1; }
sensor_args=(--width "${geometry%x*}" --height "${geometry#*x}")
ticks=$(getconf CLK_TCK)
cpu_seconds() {  # user + system CPU seconds of a live process
  awk -v t="$ticks" '{ print ($14 + $15) / t }' "/proc/$1/stat"
}
field() {  # field FILE REGEX: the first number after REGEX
  { grep -oP "$2\s*\K[0-9.]+" "$1" || true; } | head -1
}

printf 'scene %s, %s s per speed, segment lists at %s Hz, %s, evldt-lines %s %s\n' "$scene" "$seconds" "$publish_hz" "$url" \
  "${sensor_args[*]}" "${lines_args[*]:-(defaults otherwise)}"
printf '%-7s %10s %14s %18s %11s %11s %8s %10s %14s %11s %7s\n' speed "Mev/s" "batches lost" "shed/thinned (ev %)" "camera CPU" "lines CPU" threads "B/event" "latency ms" "settled p99" "F@1%"
rows=()
medians=()
best=0
for repeat in $(seq "$repeats"); do
((repeats == 1)) || echo "run $repeat of $repeats"
for speed in $speeds; do
  "$lines" --lcm-url "$url" --publish-hz "$publish_hz" --log-period-s 0 "${sensor_args[@]}" ${lines_args[@]+"${lines_args[@]}"} >"$work/lines.out" 2>"$work/lines.err" &
  lines_pid=$!
  pids+=("$lines_pid")
  for _ in $(seq 1200); do grep -q "evldt-lines ready:" "$work/lines.err" && break; sleep 0.05; done
  if $score; then
    rm -f "$work/lists.lcm"
    nice -n -10 lcm-logger --lcm-url="${url}&recv_buf_size=8388608" -c 'LINES_CAM0' -q -f "$work/lists.lcm" >/dev/null 2>&1 &
    logger_pid=$!
    pids+=("$logger_pid")
    sleep 0.3
  fi
  lines_cpu_before=$(cpu_seconds "$lines_pid")  # its start-up (building nothing yet) is not the stream's cost
  "$camera" "$recording" --lcm-url "$url" --speed "$speed" --loop --quiet --log-level warn >"$work/camera.out" 2>"$work/camera.err" &
  camera_pid=$!
  pids+=("$camera_pid")
  started=$(date +%s.%N)
  sleep "$seconds"
  camera_cpu=$(cpu_seconds "$camera_pid")
  lines_cpu=$(awk -v a="$lines_cpu_before" -v b="$(cpu_seconds "$lines_pid")" 'BEGIN { print b - a }')
  wall=$(awk -v s="$started" -v e="$(date +%s.%N)" 'BEGIN { print e - s }')
  kill -INT "$camera_pid"
  wait "$camera_pid" || true
  sleep 0.5  # the last lists
  kill -INT "$lines_pid"
  wait "$lines_pid" || true
  f=n/a
  if $score; then
    kill -INT "$logger_pid"
    wait "$logger_pid" || true
    scored_s=$(awk -v sp="$speed" -v s="$seconds" -v d="$scene_s" 'BEGIN { c = sp * s; print (c < d) ? c : d }')
    if "$eval_tool" --segments "$work/lists.lcm" --scene "$scene" --duration-s "$scored_s" --json "$work/eval.json" >/dev/null 2>&1; then
      f=$(grep -oP '"f"\s*:\s*\K[0-9.]+' "$work/eval.json" | head -1 | xargs printf "%.3f")
    fi
  fi
  rate=$(field "$work/camera.out" 'wall \([0-9.]+x\),')
  bytes=$(field "$work/camera.out" 'MB,')
  received=$(field "$work/lines.out" 'batches')
  lost=$(field "$work/lines.out" 'received,')
  events_shed=$(field "$work/lines.out" 'shed')
  batches_shed=$(field "$work/lines.out" 'not stored:')
  batches_thinned=$(field "$work/lines.out" 'shed whole,')
  events_in=$(field "$work/lines.out" 'events')
  batches_shed=${batches_shed:-0}
  batches_thinned=${batches_thinned:-0}
  events_shed=${events_shed:-0}
  shed_pct=$(awk -v s="$events_shed" -v r="${events_in:-0}" 'BEGIN { printf "%.1f", (s + r > 0) ? 100 * s / (s + r) : 0 }')
  median=$(field "$work/lines.out" 'median')
  p99=$(field "$work/lines.out" 'p99')
  settled_p99=$(field "$work/lines.out" 'the first batch: median [0-9.]+ ms, p99')
  camera_pct=$(awk -v c="$camera_cpu" -v w="$wall" 'BEGIN { printf "%.0f%%", 100 * c / w }')
  lines_pct=$(awk -v c="$lines_cpu" -v w="$wall" 'BEGIN { printf "%.0f%%", 100 * c / w }')
  threads=$(field "$work/lines.err" 'rounds on')
  printf '%-7s %10s %14s %18s %11s %11s %8s %10s %14s %11s %7s\n' "$speed" "$rate" "$lost of $received" "$batches_shed/$batches_thinned ($shed_pct%)" "$camera_pct" "$lines_pct" "$threads" "$bytes" "$median / $p99" "${settled_p99:-n/a}" "$f"
  echo "$speed ${lines_pct%\%} $shed_pct $p99 ${settled_p99:-nan} ${f/n\/a/nan} $lost" >>"$work/runs.txt"
  rows+=("{\"repeat\": $repeat, \"speed\": $speed, \"mev_s\": $rate, \"batches_received\": $received, \"batches_lost\": $lost, \"batches_shed\": $batches_shed, \"batches_thinned\": $batches_thinned, \"events_shed\": $events_shed, \"camera_cpu\": \"$camera_pct\", \"lines_cpu\": \"$lines_pct\", \"threads\": $threads, \"bytes_per_event\": $bytes, \"latency_median_ms\": $median, \"latency_p99_ms\": $p99, \"latency_settled_p99_ms\": ${settled_p99:-null}, \"live_f_1pct\": $( [[ $f == n/a ]] && echo null || echo "$f")}")
  if [[ $lost == 0 ]] && awk -v r="$rate" -v b="$best" -v p="$p99" -v m="$max_p99_ms" 'BEGIN { exit !(r > b && p < m) }'; then
    best=$rate
  fi
done
done
if ((repeats > 1)); then
  printf '\nmedians over %s runs\n%-7s %11s %16s %10s %14s %7s %16s\n' "$repeats" speed "lines CPU" "shed (events %)" "p99 ms" "settled p99" "F@1%" "runs with loss"
  medians=()
  for speed in $speeds; do
    # The median of each column of this speed's runs (nan: not measured).
    read -r cpu shed p99 settled f lossy < <(awk -v sp="$speed" '$1 == sp { n++; for (c = 2; c <= 6; c++) v[c, n] = $c; lossy += ($7 != 0) }
      END { for (c = 2; c <= 6; c++) { m = 0; for (i = 1; i <= n; i++) if (v[c, i] != "nan") x[++m] = v[c, i] + 0
              for (i = 2; i <= m; i++) for (j = i; j > 1 && x[j - 1] > x[j]; j--) { t = x[j]; x[j] = x[j - 1]; x[j - 1] = t }
              printf "%s ", m == 0 ? "nan" : (m % 2 ? x[(m + 1) / 2] : (x[m / 2] + x[m / 2 + 1]) / 2) }
            print lossy + 0 }' "$work/runs.txt")
    printf '%-7s %10s%% %15s%% %10s %14s %7s %16s\n' "$speed" "$cpu" "$shed" "$p99" "$settled" "$f" "$lossy of $repeats"
    json_number() { [[ $1 == nan ]] && echo null || echo "$1"; }
    medians+=("{\"speed\": $speed, \"lines_cpu_pct\": $cpu, \"shed_pct\": $shed, \"latency_p99_ms\": $p99, \"latency_settled_p99_ms\": $(json_number "$settled"), \"live_f_1pct\": $(json_number "$f"), \"runs_with_loss\": $lossy}")
  done
fi
echo "highest event rate held for $seconds s with zero lost batches and p99 latency < $max_p99_ms ms: $best Mev/s"
if [[ -n $json ]]; then
  {
    echo "{\"scene\": \"$scene\", \"seconds\": $seconds, \"publish_hz\": $publish_hz, \"max_p99_ms\": $max_p99_ms, \"repeats\": $repeats, \"best_mev_s\": $best, \"runs\": ["
    (IFS=,; echo "${rows[*]}")
    echo "], \"medians\": ["
    (IFS=,; echo "${medians[*]}")
    echo "]}"
  } >"$json"
  echo "wrote $json"
fi
