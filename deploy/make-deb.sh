#!/usr/bin/env bash
# Builds evldt's Debian package: deploy/make-deb.sh [BUILD_DIR] (default build/deb) configures a
# Release build with the prefix /usr, builds it, and writes BUILD_DIR/evldt_<version>_<arch>.deb
# (cmake/packaging.cmake says what it holds). Install it with: sudo apt install ./BUILD_DIR/evldt_*.deb
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/deb}
deploy/install-deps.sh dpkg-dev
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr -DEVLDT_BUILD_TESTS=OFF "${launcher[@]}" >/dev/null
cmake --build "$build" -j "$(nproc)"
(cd "$build" && cpack -G DEB -B "$PWD")
ls "$build"/evldt_*.deb
