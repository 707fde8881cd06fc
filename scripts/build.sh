#!/usr/bin/env bash
# Configures and builds tiltcal into build/ (Release, Ninja), through ccache
# when it is installed (compiler_cache.sh). Binaries land in build/bin/.
# Extra arguments go to cmake, e.g. -DTILTCAL_SANITIZE=address.
# SKIP_SETUP=1 leaves out scripts/setup.sh (scripts/test.sh installs the
# packages itself, in parts, before and beside the build).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/phase_time.sh
if [ "${SKIP_SETUP:-0}" != 1 ]; then
  scripts/setup.sh
  phase_done setup
fi
BUILD_DIR=${BUILD_DIR:-build}
source scripts/compiler_cache.sh
if [ ! -f "$BUILD_DIR/build.ninja" ] || [ $# -gt 0 ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release "${COMPILER_CACHE[@]}" "$@" >/dev/null
  phase_done configure
fi
cmake --build "$BUILD_DIR" -j "$(nproc)"
phase_done build
