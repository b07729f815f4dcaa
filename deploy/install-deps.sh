#!/usr/bin/env bash
# Installs the Debian packages evldt builds and runs with, and any given as arguments, if any is
# missing (apt-get, as root). Usage: deploy/install-deps.sh [EXTRA_PACKAGE...]
set -euo pipefail
packages=(build-essential cmake ninja-build pkg-config
  liblcm-dev liblcm-bin liblcm-java libeigen3-dev libopencv-dev libspdlog-dev libcli11-dev
  libgtest-dev libyaml-cpp-dev libsystemd-dev libsqlite3-dev liblz4-dev libzstd-dev zlib1g-dev libflatbuffers-dev flatbuffers-compiler libcpp-httplib-dev librosbag-storage-dev libhdf5-dev hdf5-filter-plugin-blosc-serial libjchart2d-java default-jdk-headless
  pybind11-dev python3-dev python3-numpy python3-pytest python3-pip python3-venv python3-setuptools python3-wheel "$@")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi
echo "evldt: installing ${missing[*]}" >&2
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "evldt: need root (or sudo) to apt-get install ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
