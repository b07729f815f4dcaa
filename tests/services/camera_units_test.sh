#!/usr/bin/env bash
# The systemd units: evldt-lines@, evldt-viz@ and evldt-logger pass `systemd-analyze
# verify`, and so do evldt-camera@ instances for live cameras: each example source of deploy/systemd/examples
# (a RAW stream over TCP, a followed RAW file, DV's AEDAT 4.0 and cAER's AEDAT 3.1 network output)
# as /etc/evldt/camera-NAME.env: the instance unit passes `systemd-analyze verify`, and its command
# line, as systemd would expand it (the example's address pointed at a test server), publishes the
# whole stream.
# Usage: camera_units_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
url="udpm://239.255.76.67:7722?ttl=0"
units=$source_dir/deploy/systemd
examples=$units/examples
sim=$build/tools/evldt-sim/evldt-sim
pacer=$build/tests/raw_pacer

"$sim" --scene boxes-6dof --duration-s 0.5 --out-dir "$work/rec" --format evt3 --quiet >/dev/null
recording=$work/rec/events.raw
"$camera" "$recording" --lcm-url "$url" --speed 0 -q >"$work/reference.out" 2>&1
events=$(field "$work/reference.out" "events +")
dv_recording=$source_dir/../shared/real/dvxplorer_person.aedat4

# The unit of camera NAME as systemd would load it here: this build's binary, environment files in
# $work/etc (evldt.env, and the example as camera-NAME.env).
instance() {  # instance NAME EXAMPLE: writes $work/units/evldt-camera@NAME.service
  mkdir -p "$work/units" "$work/etc"
  cp "$units/evldt.env" "$work/etc/evldt.env"
  cp "$2" "$work/etc/camera-$1.env"
  sed -e "s|/usr/local/bin/evldt-camera|$camera|" -e "s|/etc/evldt/|$work/etc/|g" "$units/evldt-camera@.service" \
    >"$work/units/evldt-camera@$1.service"
}
# Its ExecStart with %i and $EVLDT_CAMERA_SOURCE expanded, the example's address replaced by ADDRESS.
command_of() {  # command_of NAME ADDRESS
  local source exec_start
  source=$(grep -oP '^EVLDT_CAMERA_SOURCE=\K.*' "$work/etc/camera-$1.env")
  source=$(sed -E "s#tcp://[^ ]+#$2#; s#--follow [^ ]+#--follow $2#" <<<"$source")
  exec_start=$(grep -oP '^ExecStart=\K.*' "$work/units/evldt-camera@$1.service")
  exec_start=${exec_start//%i/$1}
  printf '%s\n' "${exec_start//\$EVLDT_CAMERA_SOURCE/$source}"
}
# Runs the command (LCM_DEFAULT_URL from the unit's environment, pointed at the test's group) to the
# end of the test server's stream: a network source (--reconnect) says "the stream ended; connecting
# again" and is then stopped as systemd stops a unit; a followed file ends by itself once the file
# stops growing (the example's 60 s made 1 s here).
run_unit() {  # run_unit NAME ADDRESS EXPECTED
  local command
  command=$(command_of "$1" "$2")
  command=${command/--follow-idle-s 60/--follow-idle-s 1}
  echo "$1: $command"
  # shellcheck disable=SC2086
  LCM_DEFAULT_URL=$url $command >"$work/$1.out" 2>"$work/$1.err" &
  local camera_pid=$!
  if [[ $command == *--reconnect* ]]; then
    wait_until "$1: the end of the stream" grep -q "the stream ended; connecting again" "$work/$1.err"
    check "$1: the camera stops at SIGTERM" stops_promptly "$camera_pid"
  else
    wait "$camera_pid"
    check "$1: the camera ends with the followed file (exit $?)" test $? -eq 0
  fi
  cat "$work/$1.out"
  check "$1: the whole stream published ($3 events)" grep -qP "events +$3 read, $3 published" "$work/$1.out"
}

for example in "$examples"/camera-*.env; do
  name=$(basename "$example" .env)
  name=${name#camera-}
  name=${name//-/_}  # a camera name: letters, digits and '_'
  instance "$name" "$example"
  systemd-analyze verify "$work/units/evldt-camera@$name.service" >"$work/$name.verify" 2>&1
  check "evldt-camera@$name verifies without a warning ($(tr '\n' ' ' <"$work/$name.verify"))" test $? -eq 0 -a ! -s "$work/$name.verify"
done
# The other units, as installed beside them (this build's binaries, the same environment files).
for unit in evldt-lines@ evldt-viz@ evldt-logger; do
  service=${unit%@}
  file=$work/units/${unit}$([[ $unit == *@ ]] && echo cam0).service
  sed -e "s|/usr/local/bin/$service|$build/services/$service/$service|" -e "s|/etc/evldt/|$work/etc/|g" "$units/$unit.service" >"$file"
  systemd-analyze verify "$file" >"$work/$service.verify" 2>&1
  check "$(basename "$file") verifies without a warning ($(tr '\n' ' ' <"$work/$service.verify"))" test $? -eq 0 -a ! -s "$work/$service.verify"
done
for name in tcp-raw follow-raw dv libcaer; do  # the example files
  check "an example for $name" test -f "$examples/camera-$name.env"
done

rm -f "$work/port"
"$pacer" "$recording" 4 tcp "$work/port" 4099 &
wait_until "the RAW server to listen" test -s "$work/port"
run_unit tcp_raw "tcp://127.0.0.1:$(cat "$work/port")" "$events"

: >"$work/growing.raw"
"$pacer" "$recording" 4 append "$work/growing.raw" 4099 &
run_unit follow_raw "$work/growing.raw" "$events"

rm -f "$work/aedat31_port"
"$build/tests/aedat31_stream_server" "$recording" "$work/aedat31_port" &
wait_until "the AEDAT 3.1 server to listen" test -s "$work/aedat31_port"
# The example's 346x260 is a DAVIS346; the test recording is 240x180: the sensor size is the one
# setting changed.
sed -i 's/--width 346 --height 260/--width 240 --height 180/' "$work/etc/camera-libcaer.env"
run_unit libcaer "tcp://127.0.0.1:$(cat "$work/aedat31_port")" "$events"

if [[ -f $dv_recording ]]; then
  "$camera" "$dv_recording" --lcm-url "$url" --speed 0 -q >"$work/dv_reference.out" 2>&1
  dv_events=$(field "$work/dv_reference.out" "events +")
  rm -f "$work/dv_port"
  "$build/tests/dv_stream_server" "$dv_recording" "$work/dv_port" &
  wait_until "the DV server to listen" test -s "$work/dv_port"
  run_unit dv "tcp://127.0.0.1:$(cat "$work/dv_port")" "$dv_events"
else
  echo "skip: the DV example's command line needs $dv_recording (../shared is absent)"
fi
finish
