#!/usr/bin/env bash
# The parsers under the sanitizers (fuzz/README.md, docs/reliability.md): builds, with
# clang, ASan + UBSan (float-cast-overflow included, stop at the first
# finding) and libFuzzer coverage, only what the I/O, bag and decode tests
# and the fuzz harnesses need (a TILTCAL_PARSERS_ONLY build: no Ceres, no
# PCL); runs those tests; then runs each harness for FUZZ_SECONDS
# (default 5) from its committed seed corpus (fuzz/corpus/).
# Tests and harnesses run JOBS (default: the number of cores) at a time; each
# harness still gets its FUZZ_SECONDS. New inputs go to a temporary
# directory; a crash leaves its input as crash-* in $BUILD_DIR/fuzz-artifacts/
# and fails the script. One step alone: --build_only, --tests_only or
# --fuzz_only (the last two build first, which has nothing to do after
# --build_only). scripts/test.sh builds while the release build's packages
# install, runs the tests beside the release build and ctest, and fuzzes
# after them.
#   scripts/sanitize_and_fuzz.sh [--build_only | --tests_only | --fuzz_only]
set -euo pipefail
cd "$(dirname "$0")/.."
MODE=${1:-}
case $MODE in
  "" | --build_only | --tests_only | --fuzz_only) ;;
  *)
    echo "usage: scripts/sanitize_and_fuzz.sh [--build_only | --tests_only | --fuzz_only]" >&2
    exit 2
    ;;
esac
source scripts/phase_time.sh
source scripts/compiler_cache.sh
BUILD_DIR=${SANITIZE_BUILD_DIR:-build-sanitize}
FUZZ_SECONDS=${FUZZ_SECONDS:-5}
JOBS=${JOBS:-$(nproc)}
FUZZERS=(ros1_bag_reader_fuzzer record_stream_fuzzer text_proto_fuzzer point_cloud2_fuzzer
         cdr_messages_fuzzer mcap_reader_fuzzer sqlite_bag_reader_fuzzer
         rosbag2_metadata_fuzzer)
# decode_bags_test first: it takes most of the time (~30 s of ~45).
TESTS=(decode_bags_test io_test checked_conversion_test imu_test ros1_unit_test
       ros1_bags_test mcap_unit_test ros2_unit_test decode_unit_test)

if [ ! -f "$BUILD_DIR/build.ninja" ]; then
  # -O1 and line tables only: half the compile time of -O2 -g, still
  # symbolised reports (the tests' own files at -O0: tests/CMakeLists.txt).
  # The precompiled headers of the release build (cmake/tiltcal_helpers.cmake)
  # and a unity build (each target's sources compiled as one file) parse the
  # headers once per build and per target.
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_UNITY_BUILD=ON \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ "${COMPILER_CACHE[@]}" \
    -DTILTCAL_SANITIZE=address,undefined -DTILTCAL_FUZZ=ON -DTILTCAL_BUILD_BENCHMARKS=OFF \
    -DTILTCAL_PARSERS_ONLY=ON >/dev/null
fi
cmake --build "$BUILD_DIR" -j "$(nproc)" --target "${FUZZERS[@]}" "${TESTS[@]}" tiltcal_decode \
  tiltcal_inspect
case $MODE in
  "" | --build_only) phase_done "sanitizer configure + build" ;;
esac
[ "$MODE" = --build_only ] && exit 0

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status_dir=$(mktemp -d)
trap 'rm -rf "$status_dir"' EXIT

# run_jobs FUNC ITEM...: FUNC ITEM for every ITEM in the background, JOBS at
# a time; the exit status of each goes to $status_dir/ITEM.
run_jobs() {
  local func=$1 item
  shift
  for item in "$@"; do
    while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n || true; done
    ( status=0; "$func" "$item" || status=$?; echo "$status" > "$status_dir/$item" ) &
  done
  wait
}
passed() { [ "$(cat "$status_dir/$1")" = 0 ]; }

sanitized_test() {
  cd "$BUILD_DIR" && "tests/$1" --gtest_brief=1 > "tests/$1.log" 2>&1
}
if [ "$MODE" != --fuzz_only ]; then
  run_jobs sanitized_test "${TESTS[@]}"
  for t in "${TESTS[@]}"; do
    passed "$t" ||
      { tail -60 "$BUILD_DIR/tests/$t.log" >&2; echo "$t failed under the sanitizers" >&2; exit 1; }
    echo "$t: passed under ASan + UBSan"
  done
  phase_done "sanitizer tests"
fi
[ "$MODE" = --tests_only ] && exit 0

artifacts=$BUILD_DIR/fuzz-artifacts
mkdir -p "$artifacts"
fuzz() {
  local fuzzer=$1 corpus fixture status=0
  corpus=$(mktemp -d)
  # The ROS 2 talker fixtures seed the ROS 2 readers when ../shared is there
  # (they are read in place, never copied into fuzz/corpus/).
  local seeds=("fuzz/corpus/${fuzzer%_fuzzer}")
  case $fuzzer in
    mcap_reader_fuzzer) fixture=../shared/fixtures/bags/ros2/mcap_talker ;;
    sqlite_bag_reader_fuzzer | rosbag2_metadata_fuzzer) fixture=../shared/fixtures/bags/ros2/sqlite3_talker ;;
    *) fixture= ;;
  esac
  if [ -n "$fixture" ] && [ -d "$fixture" ]; then seeds+=("$fixture"); fi
  "$BUILD_DIR/bin/$fuzzer" -max_total_time="$FUZZ_SECONDS" -rss_limit_mb=2048 \
    -timeout=10 -artifact_prefix="$artifacts/" "$corpus" "${seeds[@]}" \
    > "$artifacts/$fuzzer.log" 2>&1 || status=$?
  rm -rf "$corpus"
  return "$status"
}
run_jobs fuzz "${FUZZERS[@]}"
findings=0
for fuzzer in "${FUZZERS[@]}"; do
  log=$artifacts/${fuzzer}.log
  if ! passed "$fuzzer"; then
    tail -40 "$log" >&2
    echo "$fuzzer: a finding (input in $artifacts/)" >&2
    findings=1
    continue
  fi
  echo "$fuzzer: $(grep -o 'Done [0-9]* runs in [0-9]* second(s)' "$log")"
done
[ "$findings" = 0 ] || exit 1
phase_done fuzz
