#!/usr/bin/env bash
# The Debian package: made by cpack from the Release build (configured with the prefix
# /usr), named and filled as a robot's image expects, its dependencies declared (and installable
# here), then unpacked into a temporary root from which camera -> lines -> viz run on loopback:
# nothing of the build tree is needed. Skipped (77) for builds of another prefix (the sanitizer ones).
# Usage: deb_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=$1
source_dir=$2
source "$source_dir/tests/services/test_lib.sh"
url="udpm://239.255.76.67:7719?ttl=0"

prefix=$(grep -oP '^CMAKE_INSTALL_PREFIX:PATH=\K.*' "$build/CMakeCache.txt")
if [[ $prefix != /usr ]]; then
  echo "skipped: $build installs to $prefix; the package is made from a build configured with /usr"
  exit 77
fi
version=$(grep -oP '^CMAKE_PROJECT_VERSION:STATIC=\K.*' "$build/CMakeCache.txt")
arch=$(dpkg --print-architecture)
(cd "$build" && cpack -G DEB -B "$work/pkg") >"$work/cpack.out" 2>&1
check "cpack -G DEB succeeds" test $? -eq 0
deb=$work/pkg/evldt_${version}_${arch}.deb
check "the package is evldt_${version}_${arch}.deb" test -s "$deb"

# --- contents and dependencies ---------------------------------------------------------------------
dpkg-deb -c "$deb" | awk '{ print $6 }' | sed 's|^\./|/|' >"$work/contents"
for path in /usr/bin/evldt-camera /usr/bin/evldt-lines /usr/bin/evldt-viz /usr/bin/evldt-offline /usr/bin/evldt-eval \
  /usr/bin/evldt-export /usr/bin/evldt-sim /usr/bin/evldt-config /etc/evldt/evldt.env /etc/evldt/camera-cam0.env /etc/evldt/640x480.toml \
  /etc/evldt/1280x720.toml /usr/lib/systemd/system/evldt-lines@.service /usr/lib/systemd/system/evldt-camera@.service \
  /usr/lib/systemd/system/evldt-viz@.service /usr/lib/systemd/system/evldt-logger.service; do
  check "the package holds $path" grep -qx "$path" "$work/contents"
done
for path in /usr/include/evldt/segment_list_t.hpp /usr/include/evldt/client/line_subscriber.hpp; do
  check "the package holds $path" grep -qx "$path" "$work/contents"
done
check "the package holds the CMake package" grep -q '^/usr/lib/.*/cmake/evldt/evldtConfig.cmake$' "$work/contents"
check "the package holds the pkg-config file" grep -q '^/usr/lib/.*/pkgconfig/evldt.pc$' "$work/contents"
check "the package holds the media module" grep -q '^/usr/lib/.*/evldt/libevldt_media_opencv.so$' "$work/contents"
if grep -q '^EVLDT_LCMTYPES_JAR' "$build/CMakeCache.txt"; then
  check "the package holds the lcm-spy jar" grep -qx /usr/share/java/evldt_lcmtypes.jar "$work/contents"
fi
check "the package holds no Python module (built for another Python)" bash -c "! grep -q python '$work/contents'"
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
for dependency in liblcm1 liblcm-bin libopencv-core libopencv-imgproc libspdlog libstdc++6; do
  check "it depends on $dependency" grep -q "$dependency" <<<"$depends"
done
dpkg-deb -e "$deb" "$work/control"
check "the configuration files are conffiles" grep -qx /etc/evldt/evldt.env "$work/control/conffiles"
if [[ $(id -u) == 0 ]]; then
  dpkg --dry-run -i "$deb" >"$work/dry-run.out" 2>&1
  check "dpkg would install it here (every dependency met): $(tail -1 "$work/dry-run.out")" test $? -eq 0
fi

# --- the units as installed ------------------------------------------------------------------------
dpkg-deb -x "$deb" "$work/root"
for unit in "$work"/root/usr/lib/systemd/system/evldt-*.service; do
  name=$(basename "$unit")
  check "$name reads /etc/evldt/evldt.env" grep -qx 'EnvironmentFile=/etc/evldt/evldt.env' "$unit"
  binary=$(grep -oP '^ExecStart=\K\S+' "$unit")
  check "$name starts $binary, which the package or lcm's holds" \
    bash -c "grep -qx '$binary' '$work/contents' || [[ '$binary' == /usr/bin/lcm-logger ]]"
done
check "evldt.env names the installed configuration" grep -qx 'EVLDT_CONFIG=/etc/evldt/640x480.toml' "$work/root/etc/evldt/evldt.env"

# --- camera -> lines -> viz from the unpacked root -------------------------------------------------
bin=$work/root/usr/bin
"$bin/evldt-lines" --lcm-url "$url" --config "$work/root/etc/evldt/240x180.toml" --log-period-s 0 \
  >"$work/lines.out" 2>"$work/lines.err" &
lines_pid=$!
"$bin/evldt-viz" --lcm-url "$url" --headless --png-dir "$work/png" --png-period-s 0.2 --log-level debug \
  >"$work/viz.out" 2>"$work/viz.err" &
viz_pid=$!
wait_ready "$work/lines.err" evldt-lines
wait_ready "$work/viz.err" evldt-viz
"$bin/evldt-camera" --lcm-url "$url" --scene boxes-6dof --duration-s 1 -q >"$work/camera.out" 2>"$work/camera.err"
check "the packaged camera exits 0" test $? -eq 0
batches=$(field "$work/camera.out" 'batches')
wait_until "a picture from the packaged viz" bash -c "ls '$work/png' 2>/dev/null | grep -q '\\.png$'"
check "the packaged lines service stops promptly" stops_promptly "$lines_pid"
check "the packaged viz stops promptly" stops_promptly "$viz_pid"
cat "$work/lines.out"
check "the packaged lines service received every batch ($batches)" grep -qP "batches +$batches received, 0 lost" "$work/lines.out"
check "... and published segment lists" grep -qP "[1-9][0-9]* segment lists published" "$work/lines.out"
check "the packaged viz wrote pictures" bash -c "ls '$work/png' | grep -q '\\.png$'"
check "... with the packaged media module" grep -q "media module $work/root/usr/lib/.*/evldt/libevldt_media_opencv.so" "$work/viz.err"
finish
