# Shared by the service test scripts (sourced after setting $build, the build folder): the
# programs under test, checks that count failures, stopping processes, reading numbers out of
# summaries. Background jobs still running are killed and $work removed on exit.
camera=$build/services/evldt-camera/evldt-camera
lines=$build/services/evldt-lines/evldt-lines
viz=$build/services/evldt-viz/evldt-viz
offline=$build/tools/evldt-offline/evldt-offline
eval_tool=$build/tools/evldt-eval/evldt-eval
junk=$build/tests/lcm_publish_junk
probe=$build/tests/lcm_lines_probe
relay=$build/tests/lcm_lossy_relay
log_count=$build/tests/lcm_log_count
# The stock lcm-logger (LCM 1.3) queues at most 30 messages per subscription and drops the rest
# silently while its main loop waits for a core: with the services and a video encoder on two cores
# it lost batches now and then. It runs at a higher priority (where allowed; nice warns and runs it
# anyway elsewhere) and with the 8 MiB receive buffer the services ask for.
logger=(nice -n -10 lcm-logger)
logger_buffer="recv_buf_size=8388608"
work=$(mktemp -d)
failures=0
cleanup_hooks=()
cleanup() {
  for pid in $(jobs -p); do kill -9 "$pid" 2>/dev/null; done
  for hook in "${cleanup_hooks[@]}"; do eval "$hook"; done
  rm -rf "$work"
}
trap cleanup EXIT

check() {  # check DESCRIPTION COMMAND...
  local what=$1
  shift
  if "$@"; then echo "ok: $what"; else echo "FAILED: $what"; failures=$((failures + 1)); fi
}

# Every wait is for a condition, with a deadline generous enough for a loaded machine and a
# sanitizer build; a wait that times out says what it waited for.
wait_limit_s=${EVLDT_TEST_WAIT_S:-90}

wait_until() {  # wait_until DESCRIPTION COMMAND...: polls COMMAND every 50 ms until it succeeds
  local what=$1
  shift
  local deadline=$((SECONDS + wait_limit_s))
  until "$@"; do
    if ((SECONDS >= deadline)); then
      echo "timed out after ${wait_limit_s} s waiting for $what"
      return 1
    fi
    sleep 0.05
  done
}

wait_ready() {  # wait_ready LOG_FILE SERVICE: the service has logged "<SERVICE> ready:" (it is subscribed)
  wait_until "$2 to log its readiness in $(basename "$1")" grep -q "$2 ready:" "$1"
}

# The stock lcm-logger says nothing when it has subscribed: publish a marker on MARKER_CHANNEL
# until its log holds one (the logger must record that channel).
wait_logger_ready() {  # wait_logger_ready URL LOG_FILE MARKER_CHANNEL
  wait_until "lcm-logger to record into $(basename "$2")" logger_has_marker "$@"
}
logger_has_marker() {
  "$junk" "$1" "$3" 1 && sleep 0.1 && test "$("$log_count" "$2" "$3")" -gt 0
}

# lcm-logger flushes its file only when a message arrives (at most every 100 ms), so each look
# publishes a marker too: what it has received reaches the file.
log_holds() {  # log_holds URL LOG_FILE CHANNEL COUNT: the log has at least COUNT messages on CHANNEL
  "$junk" "$1" TEST_MARKER 1 && test "$("$log_count" "$2" "$3")" -ge "$4"
}

tracking_rounds() {  # tracking_rounds SUMMARY_FILE: the tracking rounds an evldt-lines summary reports
  grep -oP 'loops +[0-9]+ detection rounds, \K[0-9]+' "$1"
}

log_holds_all() {  # log_holds_all URL LOG_FILE CHANNEL COUNT: waits for log_holds, else says how many arrived
  wait_until "$4 messages on $3 in $(basename "$2")" log_holds "$@" && return 0
  echo "  $(basename "$2") holds $("$log_count" "$2" "$3") of $4 messages on $3"
  return 1
}

probe_heard_batch() {  # probe_heard_batch PROBE_OUT SEQ [EPOCH]: a segment list included batch SEQ
  awk -v seq="$2" -v epoch="${3:-}" '$1 == "list" && $6 >= seq && (epoch == "" || $3 == epoch) { found = 1 } END { exit !found }' "$1"
}

# Sends SIGTERM (or $2) and checks that the process ends promptly, printing how long it took. The
# services stop within a second on an idle machine; the limit leaves room for a loaded one.
stops_promptly() {
  local pid=$1 signal=${2:-TERM} started=$EPOCHREALTIME
  kill -s "$signal" "$pid"
  for _ in $(seq 200); do
    if ! kill -0 "$pid" 2>/dev/null; then
      wait "$pid"
      echo "stopped by SIG$signal in $(awk -v a="$started" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.0f", (b - a) * 1000 }') ms"
      return 0
    fi
    sleep 0.05
  done
  return 1
}

field() {  # field FILE REGEX: the first number after REGEX
  grep -oP "$2\s*\K[0-9.]+" "$1" | head -1
}

f_at_1_percent() {  # the F of the first tolerance (1%) in an evldt-eval JSON
  grep -oP '"f"\s*:\s*\K[0-9.]+' "$1" | head -1
}

close_to() {  # close_to A B TOLERANCE: both numbers present and |A - B| <= TOLERANCE
  [[ -n $1 && -n $2 ]] && awk -v a="$1" -v b="$2" -v tol="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= tol) }'
}

finish() {
  echo "$failures failure(s)"
  exit $((failures > 0))
}
