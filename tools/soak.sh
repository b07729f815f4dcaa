#!/usr/bin/env bash
# Soak run of the whole system (not part of CI): evldt-camera looping a scene at a steady rate ->
# evldt-lines -> evldt-viz (headless) + lcm-logger, for MINUTES. Every 10 s it samples each
# process's resident memory, CPU and open file descriptors, and evldt-lines' batches, losses and
# latency, into soak.csv, and plots them (soak.png, gnuplot). Fails if an evldt service's RSS grows
# more than 5% after the first minute (peak of the last window against the peak of the first
# window after it), if any batch is lost, or if a process dies.
# The logger writes into a rotating set of files (3 x 200 MB at most), so disk use stays bounded.
# Usage: tools/soak.sh MINUTES [--scene NAME] [--speed X] [--build DIR] [--out DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
minutes=${1:?usage: tools/soak.sh MINUTES [--scene NAME] [--speed X] [--build DIR] [--out DIR]}
[[ $minutes =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "MINUTES must be a number" >&2; exit 1; }
shift
scene=three-lines-fast
speed=0.25  # about 2 Mev/s at 640x480, the event rate of the paper's VGA recording
build=$root/build/release
out=$root/out/soak
while (($# > 0)); do
  case $1 in
    --scene) scene=$2; shift 2 ;;
    --speed) speed=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 1 ;;
  esac
done
"$root/deploy/install-deps.sh" gnuplot-nox
[[ -x $build/services/evldt-lines/evldt-lines ]] || { echo "build first: cmake --build $build" >&2; exit 1; }
"$root/deploy/multicast-route.sh"
mkdir -p "$out/log"
rm -f "$out"/log/* "$out/soak.csv"
url="udpm://239.255.76.67:7721?ttl=0"
sample_s=10

pids=()
names=()
stop_all() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
}
trap 'stop_all' EXIT
start() {  # start NAME COMMAND...: runs it in the background with its output in $out
  local name=$1
  shift
  "$@" >"$out/$name.out" 2>"$out/$name.err" &
  pids+=($!)
  names+=("$name")
}
wait_ready() {  # wait_ready SERVICE
  for _ in $(seq 1200); do
    grep -q "$1 ready:" "$out/$1.err" && return 0
    sleep 0.05
  done
  echo "$1 did not get ready; see $out/$1.err" >&2
  exit 1
}

start lcm-logger lcm-logger --lcm-url="$url" -q --rotate 2 --split-mb 200 "$out/log/soak.lcmlog"
start evldt-lines "$build/services/evldt-lines/evldt-lines" --lcm-url "$url" --log-period-s "$sample_s"
start evldt-viz "$build/services/evldt-viz/evldt-viz" --lcm-url "$url" --headless --png-dir "$out/png" --png-period-s 60
wait_ready evldt-lines
wait_ready evldt-viz
start evldt-camera "$build/services/evldt-camera/evldt-camera" --lcm-url "$url" --scene "$scene" --speed "$speed" --loop -q

ticks=$(getconf CLK_TCK)
declare -A last_cpu
header="elapsed_s"
for name in "${names[@]}"; do header+=",${name}_rss_mb,${name}_cpu_pct,${name}_fds"; done
echo "$header,batches_received,batches_lost,latency_median_ms,latency_p99_ms" >"$out/soak.csv"
echo "soak: $scene at x$speed for $minutes min; a sample every $sample_s s into $out/soak.csv"
started=$SECONDS
end=$((started + $(awk -v m="$minutes" 'BEGIN { printf "%d", m * 60 }')))
next=$((started + sample_s))
failure=""
while ((SECONDS < end)); do
  sleep $((next - SECONDS > 0 ? next - SECONDS : 0))
  next=$((next + sample_s))
  row="$((SECONDS - started))"
  for i in "${!pids[@]}"; do
    pid=${pids[$i]}
    if [[ ! -d /proc/$pid ]]; then
      failure="${names[$i]} exited (see $out/${names[$i]}.err)"
      break 2
    fi
    rss_kb=$(awk '/^VmRSS:/ { print $2 }' "/proc/$pid/status")
    cpu=$(awk -v t="$ticks" '{ print ($14 + $15) / t }' "/proc/$pid/stat")
    pct=$(awk -v c="$cpu" -v l="${last_cpu[$pid]:-0}" -v s="$sample_s" 'BEGIN { printf "%.1f", 100 * (c - l) / s }')
    last_cpu[$pid]=$cpu
    fds=$(ls "/proc/$pid/fd" | wc -l)
    row+=",$(awk -v k="$rss_kb" 'BEGIN { printf "%.1f", k / 1024 }'),$pct,$fds"
  done
  # evldt-lines' status line: "... N batches (L lost, ...), ..., latency M / P ms ..."
  status=$(grep "events stored" "$out/evldt-lines.err" | tail -1)
  received=$(grep -oP '[0-9]+(?= batches \()' <<<"$status" || echo 0)
  lost=$(grep -oP '\(\K[0-9]+(?= lost)' <<<"$status" || echo 0)
  latency=$(grep -oP 'latency \K[0-9.]+ / [0-9.]+' <<<"$status" || echo "0 / 0")
  echo "$row,$received,$lost,${latency% / *},${latency#* / }" >>"$out/soak.csv"
  printf '\r%5d s: lines RSS %s MB, %s batches, %s lost, latency p99 %s ms   ' "$((SECONDS - started))" \
    "$(cut -d, -f5 <<<"${row}")" "$received" "$lost" "${latency#* / }"
  if [[ $lost != 0 ]]; then failure="$lost batches lost"; fi
done
echo
stop_all
trap - EXIT
cat "$out/evldt-camera.out" "$out/evldt-lines.out" "$out/evldt-viz.out"
viz_lost=$(grep -oP 'batches \(\K[0-9]+(?= lost)' "$out/evldt-viz.out" || echo "?")
[[ $viz_lost == 0 ]] || failure+="${failure:+; }evldt-viz lost $viz_lost batches"
lines_lost=$(grep -oP 'received, \K[0-9]+(?= lost)' "$out/evldt-lines.out" || echo "?")
[[ $lines_lost == 0 ]] || failure+="${failure:+; }evldt-lines lost $lines_lost batches"

# Growth of each process's RSS: the peak over the last window against the peak over the first
# window after the first minute (a window is 5 min, or a third of the rest of a shorter run). Peaks,
# because a process's RSS saws up and down with its work (the camera's with each loop of the scene)
# and two single samples would measure that phase, not growth. evldt's services are judged;
# lcm-logger, Debian's stock tool, is reported only: its queue of unwritten messages (up to 100 MB)
# follows the disk's latency, not a leak of ours.
growth=$(awk -F, -v names="${names[*]}" '
  NR == 1 { next }
  { t[NR] = $1; row[NR] = $0; last = NR }
  END {
    n = split(names, name, " ")
    if (last < 2 || t[last] < 120) { print "too short: less than a minute after the first minute"; exit }
    window = (t[last] - 60) / 3; if (window > 300) window = 300
    for (r = 2; r <= last; ++r) {
      split(row[r], v, ",")
      for (i = 1; i <= n; ++i) {
        c = 2 + 3 * (i - 1)
        if (t[r] >= 60 && t[r] < 60 + window && v[c] > first[i]) first[i] = v[c]
        if (t[r] > t[last] - window && v[c] > end_peak[i]) end_peak[i] = v[c]
      }
    }
    for (i = 1; i <= n; ++i) printf "%s %.1f -> %.1f MB (%+.1f%%)\n", name[i], first[i], end_peak[i], 100 * (end_peak[i] - first[i]) / first[i]
  }' "$out/soak.csv")
echo "RSS, peak of the first window after the first minute -> peak of the last window:"
echo "$growth" | sed 's/^/  /'
if grep -q "too short" <<<"$growth"; then
  failure+="${failure:+; }run shorter than two minutes"
fi
while read -r name _ _ _ _ pct; do
  pct=${pct//[()%+]/}
  [[ $name == evldt-* ]] || continue
  awk -v p="$pct" 'BEGIN { exit !(p > 5) }' && failure+="${failure:+; }$name RSS grew $pct%"
done < <(grep -- "->" <<<"$growth")

gnuplot <<EOF
set datafile separator ","
set terminal pngcairo size 1200,900 noenhanced
set output "$out/soak.png"
set multiplot layout 3,1 title "evldt soak: $scene x$speed, $minutes min"
set key outside right
set xlabel "elapsed s"
set ylabel "RSS MB"
plot for [i=0:$((${#names[@]} - 1))] "$out/soak.csv" using 1:(column(2 + 3 * i)) skip 1 with lines title word("${names[*]}", i + 1)
set ylabel "CPU %"
plot for [i=0:$((${#names[@]} - 1))] "$out/soak.csv" using 1:(column(3 + 3 * i)) skip 1 with lines title word("${names[*]}", i + 1)
set ylabel "latency ms / lost"
n = 1 + 3 * ${#names[@]}  # the columns before batches_received
plot "$out/soak.csv" using 1:(column(n + 3)) skip 1 with lines title "median latency", \
     "" using 1:(column(n + 4)) skip 1 with lines title "p99 latency", \
     "" using 1:(column(n + 2)) skip 1 with lines title "batches lost"
unset multiplot
EOF
echo "wrote $out/soak.csv and $out/soak.png"
if [[ -n $failure ]]; then
  echo "soak FAILED: $failure"
  exit 1
fi
echo "soak passed: no batch lost, no RSS growth above 5% after the first minute"
