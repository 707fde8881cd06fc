#!/usr/bin/env bash
# Configures and builds tiltcal into build/ (Release, Ninja), through ccache
# when it is installed (compiler_cache.sh). Binaries land in build/bin/.
# Extra arguments go to cmake, e.g. -DTILTCAL_SANITIZE=address.
# SETUP_BUILD_ONLY=1 installs only the build dependencies (setup.sh
# --build_only; scripts/test.sh installs the test ones beside the build).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/phase_time.sh
if [ "${SETUP_BUILD_ONLY:-0}" = 1 ]; then
  scripts/setup.sh --build_only
else
  scripts/setup.sh
fi
phase_done setup
BUILD_DIR=${BUILD_DIR:-build}
source scripts/compiler_cache.sh
if [ ! -f "$BUILD_DIR/build.ninja" ] || [ $# -gt 0 ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release "${COMPILER_CACHE[@]}" "$@" >/dev/null
  phase_done configure
fi
cmake --build "$BUILD_DIR" -j "$(nproc)"
phase_done build
