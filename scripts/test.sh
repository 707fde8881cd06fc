#!/usr/bin/env bash
# Installs dependencies when needed, builds with warnings as errors and runs
# every test, then the sanitizer and fuzz runs of the parsers. Tests that
# need ../shared/fixtures skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/phase_time.sh
# The packages arrive in three parts, so that both cores compile while the
# rest installs (dpkg unpacks on one core). First, in the foreground, what
# the sanitizer build of the parsers needs (clang, protobuf, the
# compression libraries: a few packages); that build starts at once in a
# background job (scripts/sanitize_and_fuzz.sh, the parsers under ASan +
# UBSan; SKIP_SANITIZERS=1 leaves it out). Then, in the foreground, the
# rest of what the release build needs (Ceres, PCL: about 100 packages),
# and the release build. Once the build's packages are in, the background
# job installs what only the tests need (the oracles, the browser, and
# Slurm and munge so that the one-node cluster test pipeline.slurm runs
# rather than skips); ctest waits for them. When both its build and those
# packages are done, it runs the sanitizer tests. The fuzzing runs after
# ctest.
scripts/setup.sh --parsers_only
phase_done "setup of the parsers' build dependencies"
sanitizers=1
[ "${SKIP_SANITIZERS:-0}" != 1 ] || sanitizers=0
background_log=$(mktemp)
build_setup_done=$(mktemp -u)  # made when the release build's packages are in
test_setup_done=$(mktemp -u)   # made when the test dependencies are in
# Its own process group, so that an early exit stops the whole job. Where
# the kernel groups each session for scheduling (autogroups), the job's
# nice counts only within it, and it shares the cores evenly with the
# foreground (the install, then the build); it has long finished when ctest
# ends. One apt at a time: it installs after the foreground's install.
setsid nice -n 10 bash -c 'set -euo pipefail
  sanitizer_build=
  if [ "$3" = 1 ]; then
    scripts/sanitize_and_fuzz.sh --build_only &
    sanitizer_build=$!
  fi
  source scripts/phase_time.sh
  while [ ! -e "$1" ]; do sleep 1; done
  phase_done "wait for the release build'"'"'s packages (background)"
  scripts/setup.sh --cluster
  phase_done "setup of the test dependencies (background)"
  touch "$2"
  [ -n "$sanitizer_build" ] || exit 0
  wait "$sanitizer_build"
  exec scripts/sanitize_and_fuzz.sh --tests_only' \
  background "$build_setup_done" "$test_setup_done" "$sanitizers" > "$background_log" 2>&1 &
background=$!
trap 'kill -- -"$background" 2> /dev/null || true
      rm -f "$background_log" "$build_setup_done" "$test_setup_done"' EXIT
background_failed() {
  cat "$background_log" >&2
  echo "$1" >&2
  exit 1
}
scripts/setup.sh --build_only
touch "$build_setup_done"
phase_done "setup of the build dependencies"
# Tests on, whatever an earlier configure of the build directory chose; the
# benchmarks (bench/, run by hand, never by a test) left out.
SKIP_SETUP=1 scripts/build.sh -DTILTCAL_WERROR=ON -DTILTCAL_BUILD_TESTS=ON \
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
