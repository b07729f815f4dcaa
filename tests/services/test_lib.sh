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

# Sends SIGTERM (or $2) and checks the process is gone within a second.
stops_within_a_second() {
  local pid=$1 signal=${2:-TERM}
  kill -s "$signal" "$pid"
  for _ in $(seq 20); do
    kill -0 "$pid" 2>/dev/null || { wait "$pid"; return 0; }
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
