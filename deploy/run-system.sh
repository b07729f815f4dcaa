#!/usr/bin/env bash
# Starts the whole system on one host: evldt-lines, evldt-viz (headless, writing an mp4 and PNG
# snapshots, or a window with --window; a web view with --http), lcm-logger, and evldt-camera; stops
# them all cleanly when the camera's source ends (unless --loop) or on Ctrl-C, then prints where the
# outputs are.
# Usage: deploy/run-system.sh [--out DIR] [--camera NAME] [--window] [--http [ADDR:]PORT] [-- CAMERA_ARGS...]
#   CAMERA_ARGS select the source (default: --scene boxes-6dof), e.g. -- recording.raw --speed 2 --loop
# Uses the binaries in build/release (build them first, or use deploy/demo.sh), and LCM_DEFAULT_URL
# (default: udpm://239.255.76.67:7667?ttl=0, this host only).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${EVLDT_BIN:-$root/build/release}
out=$root/out/system
camera_name=cam0
window=0
http=()
while (($#)); do
  case $1 in
    --out) out=$2; shift 2 ;;
    --camera) camera_name=$2; shift 2 ;;
    --window) window=1; shift ;;
    --http) http=(--http "$2"); shift 2 ;;
    --) shift; break ;;
    -h|--help) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "run-system.sh: unknown argument $1 (see --help)" >&2; exit 1 ;;
  esac
done
camera_args=("$@")
((${#camera_args[@]})) || camera_args=(--scene boxes-6dof)
export LCM_DEFAULT_URL=${LCM_DEFAULT_URL:-"udpm://239.255.76.67:7667?ttl=0"}
for program in services/evldt-camera/evldt-camera services/evldt-lines/evldt-lines services/evldt-viz/evldt-viz; do
  [[ -x $bin/$program ]] || { echo "run-system.sh: $bin/$program missing: build first (deploy/demo.sh does)" >&2; exit 1; }
done
"$root/deploy/multicast-route.sh"
mkdir -p "$out"
rm -rf "$out/png"

pids=()
stop_all() {
  trap - INT TERM
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
}
trap 'stop_all; exit 130' INT TERM

# The logger needs the receive buffer the services ask for, and a higher priority where allowed: the
# stock lcm-logger keeps only 30 messages per subscription while it waits for a core.
logger_url=$LCM_DEFAULT_URL
if [[ $logger_url == udpm://* && $logger_url != *recv_buf_size* ]]; then
  [[ $logger_url == *\?* ]] && logger_url+="&" || logger_url+="?"
  logger_url+="recv_buf_size=8388608"
fi
nice -n -10 lcm-logger --lcm-url="$logger_url" -f -q "$out/run.lcmlog" &
pids+=($!)
"$bin/services/evldt-lines/evldt-lines" --camera "$camera_name" >"$out/lines.txt" 2>"$out/lines.log" &
pids+=($!)
viz_args=(--camera "$camera_name" --png-dir "$out/png" --png-period-s 1 "${http[@]}")
((window)) || viz_args+=(--headless --video "$out/viz.mp4")
"$bin/services/evldt-viz/evldt-viz" "${viz_args[@]}" >"$out/viz.txt" 2>"$out/viz.log" &
pids+=($!)
# The subscribers are up before the first batch: each service logs "<name> ready:" once subscribed.
wait_ready() {  # wait_ready LOG SERVICE
  for _ in $(seq 600); do
    grep -q "$2 ready:" "$1" && return 0
    sleep 0.05
  done
  echo "evldt: $2 did not get ready within 30 s; its log: $1" >&2
  stop_all
  exit 1
}
wait_ready "$out/lines.log" evldt-lines
wait_ready "$out/viz.log" evldt-viz
((${#http[@]} == 0)) || echo "evldt: $(grep -oP 'web view at \S+' "$out/viz.log")"
echo "evldt: camera ${camera_args[*]} -> EVENTS_${camera_name^^} -> evldt-lines -> LINES_${camera_name^^} (Ctrl-C stops all)"
camera_status=0
"$bin/services/evldt-camera/evldt-camera" --camera "$camera_name" "${camera_args[@]}" >"$out/camera.txt" 2> >(tee "$out/camera.log" >&2) &
camera_pid=$!
pids+=("$camera_pid")  # a stop signal to this script stops the camera too
wait "$camera_pid" || camera_status=$?
sleep 0.3  # the last segment lists reach the logger
stop_all
cat "$out/camera.txt" "$out/lines.txt" "$out/viz.txt"
echo
echo "outputs in $out:"
echo "  run.lcmlog      everything on the bus (lcm-logger): replay with lcm-logplayer, inspect with deploy/lcm-spy.sh"
((window)) || echo "  viz.mp4         what evldt-viz drew: events (grey), whole lines (cyan, with ids) over segments (yellow detected, green good, red bad)"
echo "  png/            evldt-viz snapshots, one a second"
echo "  *.txt, *.log    each service's summary and log"
exit "$camera_status"
