#!/usr/bin/env bash
# Configures and builds tiltcal into build/ (Release, Ninja), through ccache
# when it is installed (compiler_cache.sh). Binaries land in build/bin/.
# Extra arguments go to cmake, e.g. -DTILTCAL_SANITIZE=address.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/phase_time.sh
scripts/setup.sh
phase_done setup
BUILD_DIR=${BUILD_DIR:-build}
source scripts/compiler_cache.sh
if [ ! -f "$BUILD_DIR/build.ninja" ] || [ $# -gt 0 ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release "${COMPILER_CACHE[@]}" "$@" >/dev/null
  phase_done configure
fi
cmake --build "$BUILD_DIR" -j "$(nproc)"
phase_done build
