#!/usr/bin/env bash
# One run per dataset: two makes started together on one dataset, 8 times.
# Makefile.pipeline holds a lock on out/ for the whole run, so the second
# make waits (saying so) and then finds everything up to date: both exit 0,
# every stage ran once per sequence, every output is present and newer than
# its inputs (make -q: nothing to do). Stub stage binaries that take a
# moment and log every call.
#   makefile_lock_test.sh [MAKEFILE] [TRIALS]
set -uo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
MAKEFILE=${1:-$SRC/Makefile.pipeline}
TRIALS=${2:-8}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
BIN=$WORK/bin
DATA=$WORK/data
mkdir -p "$BIN" "$DATA"
source "$(dirname "$0")/stub_stages.sh"
make_stub_stages "$BIN"
export STUB_SLEEP_S=0.05
echo 'imu_height_m: 0.3' > "$DATA/rig.txtpb"
touch "$DATA/seq_a.bag" "$DATA/seq_b.bag" "$DATA/seq_c.bag"
export STUB_LOG=$WORK/stub.log
MAKE=(make --no-print-directory -f "$MAKEFILE" DATASET="$DATA" BIN="$BIN" PYTHON="$BIN/python")
failures=0
fail() { echo "FAIL: trial $trial: $*" >&2; failures=$((failures + 1)); }
waited=0
for ((trial = 1; trial <= TRIALS; trial++)); do
  rm -rf "$DATA/out"
  : > "$STUB_LOG"
  "${MAKE[@]}" -j2 all > "$WORK/first.out" 2>&1 &
  first=$!
  "${MAKE[@]}" -j2 all > "$WORK/second.out" 2>&1 &
  second=$!
  wait "$first"; first_status=$?
  wait "$second"; second_status=$?
  [ "$first_status" -eq 0 ] || fail "first make exited $first_status: $(tail -c 400 "$WORK/first.out")"
  [ "$second_status" -eq 0 ] || fail "second make exited $second_status: $(tail -c 400 "$WORK/second.out")"
  for s in seq_a seq_b seq_c; do
    for f in imu.binpb scans.binpb.lz4 ground.binpb gravity.txtpb calibration.txtpb ground.csv; do
      [ -s "$DATA/out/$s/$f" ] || fail "out/$s/$f missing"
    done
    runs=$(grep -c "^tiltcal_decode .*--bag='\?$DATA/$s.bag" "$STUB_LOG")
    [ "$runs" -eq 1 ] || fail "decode ran $runs times for $s"
  done
  for f in calibration.txtpb repeatability.txt report.html extrinsic_positions.png; do
    [ -s "$DATA/out/$f" ] || fail "out/$f missing"
  done
  "${MAKE[@]}" -q all || fail "make -q: outputs not up to date after both runs"
  grep -qh "waiting for another make" "$WORK/first.out" "$WORK/second.out" && waited=$((waited + 1))
done
echo "$TRIALS trials, $waited with a make that waited and said so"
[ "$waited" -gt 0 ] || { echo "FAIL: no make ever waited" >&2; failures=$((failures + 1)); }
if [ "$failures" -gt 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo PASS
