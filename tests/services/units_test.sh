#!/usr/bin/env bash
# The systemd units as installed: every LCM URL a unit's command line gets (its --lcm-url, or
# LCM_DEFAULT_URL from its EnvironmentFile) is a multicast URL with the 8 MiB receive buffer, so
# that no receiver (lcm-logger above all) records with the lossy default.
# Usage: units_test.sh SOURCE_DIR
set -uo pipefail
units=$1/deploy/systemd
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# The variables the units' EnvironmentFiles set (evldt.env and camera-*.env), as systemd reads them.
declare -A env
while IFS='=' read -r key value; do
  [[ -z $key || $key == \#* ]] && continue
  env[$key]=$value
done < <(cat "$units"/evldt.env "$units"/camera-*.env)
expand() {  # expand LINE: ${VAR} and $VAR from the environment files
  local line=$1 key
  for key in "${!env[@]}"; do
    line=${line//\$\{$key\}/${env[$key]}}
    line=${line//\$$key/${env[$key]}}
  done
  printf '%s\n' "$line"
}
check_url() {  # check_url WHERE URL
  [[ $2 == udpm://* ]] || fail "$1: $2 is no multicast URL"
  [[ $2 == *recv_buf_size=8388608* ]] || fail "$1: $2 has no recv_buf_size=8388608"
}

check_url "evldt.env LCM_DEFAULT_URL" "${env[LCM_DEFAULT_URL]:-}"
units_seen=0
for unit in "$units"/*.service; do
  name=$(basename "$unit")
  grep -q '^EnvironmentFile=/etc/evldt/evldt.env$' "$unit" || fail "$name does not read /etc/evldt/evldt.env"
  exec_start=$(grep '^ExecStart=' "$unit") || { fail "$name has no ExecStart"; continue; }
  command=$(expand "${exec_start#ExecStart=}")
  urls=$(grep -oP -- '--lcm-url[= ]\K\S+' <<<"$command")
  if [[ -n $urls ]]; then
    while read -r url; do check_url "$name" "$url"; done <<<"$urls"
  else
    # No --lcm-url: LCM and evldt take LCM_DEFAULT_URL from the environment, checked above.
    [[ $command == */evldt-* ]] || fail "$name: $command takes no LCM URL and is no evldt service"
  fi
  units_seen=$((units_seen + 1))
done
[[ $units_seen -ge 4 ]] || fail "only $units_seen units found in $units"
[[ $(grep -c 'lcm-logger' "$units"/evldt-logger.service) -ge 1 ]] || fail "no lcm-logger unit"
if ((failures > 0)); then
  echo "units: $failures failure(s)"
  exit 1
fi
echo "units: every LCM URL of $units_seen units has the 8 MiB receive buffer"
