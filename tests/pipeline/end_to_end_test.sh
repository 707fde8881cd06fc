#!/usr/bin/env bash
# End to end on a short simulated dataset: tiltcal_simulate writes two flat
# sequences (real ROS1 bags + truth) and the rig, Makefile.pipeline runs every
# stage with -j2, and the repeatability report must list both sequences with
# their errors against the truth within loose bounds; then a dataset of one
# bag ends with its dataset calibration and its page.
#   end_to_end_test.sh BUILD_DIR
set -euo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${1:?usage: end_to_end_test.sh BUILD_DIR}" && pwd)/bin
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
DATA=$WORK/flat
mkdir -p "$DATA"
fail() { echo "FAIL: $*" >&2; exit 1; }

source "$(dirname "$0")/flat_pair_dataset.sh"
simulate_flat_pair "$BIN" "$SRC" "$WORK" "$DATA"

make --no-print-directory -s -f "$SRC/Makefile.pipeline" DATASET="$DATA" BIN="$BIN" -j2 \
  > "$WORK/make.log" 2>&1 || { tail -20 "$WORK/make.log"; fail "the pipeline failed"; }

for s in seq_1 seq_2; do
  for f in imu.binpb scans.binpb.lz4 ground.binpb gravity.txtpb calibration.txtpb ground.csv; do
    [ -s "$DATA/out/$s/$f" ] || fail "no out/$s/$f"
  done
done
# Clean sequences: usable (OK, or WEAK naming what came from the rig).
for s in seq_1 seq_2; do
  grep -qE "^verdict: (OK|WEAK)$" "$DATA/out/$s/calibration.txtpb" ||
    fail "$s: verdict $(grep "^verdict" "$DATA/out/$s/calibration.txtpb")"
done
table=$DATA/out/repeatability.txt
[ -s "$table" ] && [ -s "$DATA/out/repeatability.csv" ] || fail "no repeatability report"
cat "$table"
grep -q "seq_1" "$table" && grep -q "seq_2" "$table" || fail "the report misses a sequence"

# Errors against the truth, from the CSV: rotation deg, x/y/z cm, tau ms, with
# the defaults (flat + distance residuals on this level ground). The 20 s
# sequences (a 10 x 5 m figure-eight at 1.2 m/s, about two thirds of a loop)
# hold less information on the angle of C_bl about the vertical than the
# 40-60 s ones, whose rotation target is 0.1 deg (its sigma here: 0.11-0.27 deg), so
# rotation is held to 0.25 deg; every axis to 1 cm, tau to 0.5 ms. Measured:
# rotation 0.089 / 0.012 deg, x/y at most 0.82 cm, z 0.01 cm, tau 0.09-0.32 ms.
awk -F, 'function abs(v) { return v < 0 ? -v : v }
NR > 1 && $1 ~ /^seq_/ {
  if ($9 == "") { print "FAIL: no error columns for " $1; bad = 1 }
  else if ($9 > 0.25 || abs($10) > 1 || abs($11) > 1 || abs($12) > 1 || abs($13) > 0.5) {
    print "FAIL: " $1 " errors rot " $9 " deg, x " $10 " cm, y " $11 " cm, z " $12 " cm, tau " $13 " ms"
    bad = 1
  }
} END { exit bad }' "$DATA/out/repeatability.csv" || fail "calibration errors too large"

if /usr/bin/python3 -c 'import matplotlib' 2> /dev/null; then
  for f in extrinsic_positions.png extrinsic_spread.png seq_1/ground_timeline.png; do
    [ -s "$DATA/out/$f" ] || fail "no plot out/$f"
  done
fi
info=$("$BIN/tiltcal_inspect" info "$DATA/out/seq_1/scans.binpb.lz4")
grep -qE "^records: 19[0-9]$" <<<"$info" || fail "inspect info does not count the scans"

# One bag and a rig in a folder is a dataset, and the rig needs no
# extrinsic: a first user's rig (topics, IMU height) without imu_from_lidar.
# make ends with the dataset calibration (that sequence's, with a reason
# saying there was no check between sequences) and the page; the starting
# extrinsic came from the motion alone, and the errors against the truth
# stay within the bounds above.
ONE=$WORK/one_bag
mkdir -p "$ONE"
sed '/^imu_from_lidar {/,/^}/d' "$DATA/rig.txtpb" > "$ONE/rig.txtpb"
! grep -q imu_from_lidar "$ONE/rig.txtpb" || fail "the rig still has imu_from_lidar"
cp -p "$DATA/seq_1.bag" "$DATA/seq_1.truth.txtpb" "$ONE/"
make --no-print-directory -s -f "$SRC/Makefile.pipeline" DATASET="$ONE" BIN="$BIN" -j2 \
  > "$WORK/one.log" 2>&1 || { tail -20 "$WORK/one.log"; fail "make on a dataset of one bag failed"; }
grep -q "guess_source: NONE" "$ONE/out/seq_1/rig.txtpb" || fail "one bag: the start was not from the motion"
grep -q "starting extrinsic: no guess" "$ONE/out/seq_1/calibration.txtpb" ||
  fail "one bag: the calibration does not say where its start came from"
awk -F, 'function abs(v) { return v < 0 ? -v : v }
NR > 1 && $1 == "seq_1" {
  found = 1
  if ($9 == "" || $9 > 0.25 || abs($10) > 1 || abs($11) > 1 || abs($12) > 1 || abs($13) > 0.5) {
    print "FAIL: no rig extrinsic: errors rot " $9 " deg, x " $10 " cm, y " $11 " cm, z " $12 " cm, tau " $13 " ms"
    bad = 1
  }
} END { exit bad || !found }' "$ONE/out/repeatability.csv" || fail "one bag without a rig extrinsic: errors too large"
for f in calibration.txtpb report.html repeatability.txt; do
  [ -s "$ONE/out/$f" ] || fail "one bag: no out/$f"
done
grep -qE "^verdict: (OK|WEAK)$" "$ONE/out/calibration.txtpb" || fail "one bag: dataset verdict"
grep -q "one sequence: no consistency check between sequences" "$ONE/out/calibration.txtpb" ||
  fail "one bag: the dataset calibration does not say it had one sequence"
if command -v chromium > /dev/null; then
  dom=$(chromium --headless --no-sandbox --disable-gpu --no-first-run \
    --user-data-dir="$WORK/chromium" --virtual-time-budget=2000 \
    --dump-dom "file://$ONE/out/report.html" 2> /dev/null) || fail "one bag: chromium failed"
  [ "$(grep -o '<section class="sequence"' <<<"$dom" | wc -l)" = 1 ] ||
    fail "one bag: the page does not show one sequence"
  grep -q "one sequence: no consistency check between sequences" <<<"$dom" ||
    fail "one bag: the page does not say there was one sequence"
  grep -q "starting extrinsic: no guess" <<<"$dom" ||
    fail "one bag: the page does not say where the starting extrinsic came from"
else
  echo "chromium is not installed (scripts/setup.sh installs it): the one-bag page not opened"
fi
echo PASS
