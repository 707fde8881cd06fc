#!/usr/bin/env bash
# Installs dependencies when needed, builds with warnings as errors and runs
# every test, then the sanitizer and fuzz runs of the parsers. Tests that
# need ../shared/fixtures skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
# Slurm and munge too, so that the one-node cluster test (pipeline.slurm)
# runs rather than skips; build.sh installs the rest.
scripts/setup.sh --cluster
# The parsers under ASan + UBSan and a few seconds of fuzzing each
# (scripts/sanitize_and_fuzz.sh); SKIP_SANITIZERS=1 leaves them out. Their
# clang build and their tests run beside the release build and ctest at a
# lower priority, on the cores those leave idle (a link, the last long
# tests); their phase times follow ctest's (their whole output when they
# fail), then the fuzzing runs.
sanitizers=0
if [ "${SKIP_SANITIZERS:-0}" != 1 ]; then
  sanitizers=1
  sanitizer_log=$(mktemp)
  # Its own process group, so that an early exit stops the whole run.
  setsid nice -n 10 scripts/sanitize_and_fuzz.sh --no_fuzz > "$sanitizer_log" 2>&1 &
  sanitizer_build=$!
  trap 'kill -- -"$sanitizer_build" 2> /dev/null || true; rm -f "$sanitizer_log"' EXIT
fi
# Tests on, whatever an earlier configure of the build directory chose; the
# benchmarks (bench/, run by hand, never by a test) left out.
scripts/build.sh -DTILTCAL_WERROR=ON -DTILTCAL_BUILD_TESTS=ON -DTILTCAL_BUILD_BENCHMARKS=OFF
source scripts/phase_time.sh
# One test more than the cores: some wait much of their time (make's lock
# trials, the Slurm daemons, the browser), and a core would stay idle.
(cd "${BUILD_DIR:-build}" && ctest --output-on-failure -j "$(($(nproc) + 1))" "$@")
phase_done ctest
if [ "$sanitizers" = 1 ]; then
  status=0
  wait "$sanitizer_build" || status=$?
  [ "$status" = 0 ] ||
    { cat "$sanitizer_log" >&2; echo "the sanitizer build or tests failed" >&2; exit 1; }
  grep "^phase: " "$sanitizer_log" >&2
  grep "passed under" "$sanitizer_log" || true
  phase_done "sanitizer build and tests, the rest after ctest"
  scripts/sanitize_and_fuzz.sh --fuzz_only
fi
