#!/usr/bin/env bash
# Installs dependencies when needed, builds with warnings as errors and runs
# every test, then the sanitizer and fuzz runs of the parsers. Tests that
# need ../shared/fixtures skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
# Slurm and munge too, so that the one-node cluster test (pipeline.slurm)
# runs rather than skips; build.sh installs the rest.
scripts/setup.sh --cluster
# Tests on, whatever an earlier configure of the build directory chose; the
# benchmarks (bench/, run by hand, never by a test) left out.
scripts/build.sh -DTILTCAL_WERROR=ON -DTILTCAL_BUILD_TESTS=ON -DTILTCAL_BUILD_BENCHMARKS=OFF
source scripts/phase_time.sh
# One test more than the cores: some wait much of their time (make's lock
# trials, the Slurm daemons, the browser), and a core would stay idle.
(cd "${BUILD_DIR:-build}" && ctest --output-on-failure -j "$(($(nproc) + 1))" "$@")
phase_done ctest
# The parsers under ASan + UBSan and a few seconds of fuzzing each
# (scripts/sanitize_and_fuzz.sh); SKIP_SANITIZERS=1 leaves them out.
if [ "${SKIP_SANITIZERS:-0}" != 1 ]; then
  scripts/sanitize_and_fuzz.sh
fi
