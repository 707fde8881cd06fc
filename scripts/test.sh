#!/usr/bin/env bash
# Installs dependencies when needed, builds with warnings as errors and runs
# every test. Tests that need ../shared/fixtures skip with a message when it
# is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh -DTILTCAL_WERROR=ON
cd "${BUILD_DIR:-build}"
ctest --output-on-failure -j "$(nproc)" "$@"
