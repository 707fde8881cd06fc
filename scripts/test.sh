#!/usr/bin/env bash
# Installs dependencies when needed, builds with warnings as errors and runs
# every test, then the sanitizer and fuzz runs of the parsers. Tests that
# need ../shared/fixtures skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/phase_time.sh
# What the build needs first. The rest (the test oracles, the browser,
# clang, and Slurm and munge so that the one-node cluster test
# pipeline.slurm runs rather than skips) installs in the background while
# the release build compiles; ctest waits for it.
scripts/setup.sh --build_only
phase_done "setup of the build dependencies"
# After it, in the same background job, the parsers under ASan + UBSan and
# a few seconds of fuzzing each (scripts/sanitize_and_fuzz.sh);
# SKIP_SANITIZERS=1 leaves them out. Their clang build and their tests run
# beside the release build and ctest; their phase times follow ctest's
# (their whole output when they fail), then the fuzzing runs.
sanitizers=1
[ "${SKIP_SANITIZERS:-0}" != 1 ] || sanitizers=0
background_log=$(mktemp)
test_setup_done=$(mktemp -u)  # made when the test dependencies are in
# Its own process group, so that an early exit stops the whole job. Where
# the kernel groups each session for scheduling (autogroups), the job's
# nice counts only within it, and it shares the cores evenly with the build;
# it has then long finished when ctest ends.
setsid nice -n 10 bash -c 'set -euo pipefail
  source scripts/phase_time.sh
  scripts/setup.sh --cluster
  phase_done "setup of the test dependencies (background)"
  touch "$1"
  [ "$2" = 0 ] || exec scripts/sanitize_and_fuzz.sh --no_fuzz' \
  background "$test_setup_done" "$sanitizers" > "$background_log" 2>&1 &
background=$!
trap 'kill -- -"$background" 2> /dev/null || true; rm -f "$background_log" "$test_setup_done"' EXIT
background_failed() {
  cat "$background_log" >&2
  echo "$1" >&2
  exit 1
}
# Tests on, whatever an earlier configure of the build directory chose; the
# benchmarks (bench/, run by hand, never by a test) left out.
SETUP_BUILD_ONLY=1 scripts/build.sh -DTILTCAL_WERROR=ON -DTILTCAL_BUILD_TESTS=ON \
  -DTILTCAL_BUILD_BENCHMARKS=OFF
source scripts/phase_time.sh  # the clock restarts after build.sh's own phases
while [ ! -e "$test_setup_done" ]; do
  if ! kill -0 "$background" 2> /dev/null; then
    [ -e "$test_setup_done" ] || background_failed "the setup of the test dependencies failed"
  fi
  sleep 1
done
phase_done "wait for the test dependencies"
# One test more than the cores: some wait much of their time (make's lock
# trials, the Slurm daemons, the browser), and a core would stay idle.
(cd "${BUILD_DIR:-build}" && ctest --output-on-failure -j "$(($(nproc) + 1))" "$@")
phase_done ctest
status=0
wait "$background" || status=$?
[ "$status" = 0 ] || background_failed "the sanitizer build or tests failed"
grep "^phase: " "$background_log" >&2
if [ "$sanitizers" = 1 ]; then
  grep "passed under" "$background_log" || true
  phase_done "sanitizer build and tests, the rest after ctest"
  scripts/sanitize_and_fuzz.sh --fuzz_only
fi
