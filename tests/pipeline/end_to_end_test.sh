#!/usr/bin/env bash
# End to end on a short simulated dataset: two flat sequences (real ROS1
# bags + truth) and the rig that tiltcal_simulate wrote, run through every
# stage by Makefile.pipeline with -j2 (both by the CTest fixture
# pipeline_flat_pair, flat_pair_fixture.sh), and the repeatability report
# must list both sequences with their errors against the truth within loose
# bounds; then the verify target
# checks the dataset's calibration against the sequences (it holds; bumped by
# 2 deg of yaw and 3 cm it moved, named), a dataset of one bag ends with its
# dataset calibration, its page and its check, and short drives that turn
# too little cannot tell; the pages are opened in chromium.
#   end_to_end_test.sh BUILD_DIR
set -euo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=$(cd "${1:?usage: end_to_end_test.sh BUILD_DIR}" && pwd)
BIN=$BUILD/bin
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
DATA=$WORK/flat
fail() { echo "FAIL: $*" >&2; exit 1; }

# The fixture's run, copied (the checks below write into the dataset).
source "$(dirname "$0")/flat_pair_dataset.sh"
FIXTURE=$(flat_pair_fixture "$BUILD")
[ -d "$FIXTURE/local/flat/out" ] ||
  fail "no $FIXTURE/local/flat/out: ctest runs tests/pipeline/flat_pair_fixture.sh first"
cp -a "$FIXTURE/local/flat" "$DATA"

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
# the defaults (flat + distance residuals on this level ground). The 12 s
# sequences (14 m of a 10 x 5 m figure-eight at 1.2 m/s) hold less
# information on the angle of C_bl about the vertical than the 40-60 s ones,
# whose rotation target is 0.1 deg, so rotation is held to 0.25 deg; every
# axis to 1 cm, tau to 0.5 ms. Measured: rotation 0.042 / 0.068 deg, x/y at
# most 0.54 cm, z 0.03 cm, tau 0.105 / 0.245 ms.
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
grep -qE "^records: 11[0-9]$" <<<"$info" || fail "inspect info does not count the scans"

# The check against a stored calibration (here the dataset's own). These 12 s
# sequences notice about 0.4 deg, 2 cm and 0.7 ms (measured: 0.384 / 0.386
# deg, 17.6 / 16.9 mm, 0.67 / 0.70 ms), at the edge of the defaults' 2 cm
# for 40 s ones (stages/verify/README.md): the dataset's params/verify.txtpb
# asks for 1 deg, 3 cm and 3 ms.
mkdir -p "$DATA/params"
sed -e 's/^\(  rotation_deg:\).*/\1 1.0/' -e 's/^\(  translation_m:\).*/\1 0.03/' \
  -e 's/^\(  time_offset_s:\).*/\1 0.003/' \
  "$SRC/stages/verify/default_params.txtpb" > "$DATA/params/verify.txtpb"
verify() {  # verify DATASET REFERENCE LOG: make's exit status
  local status=0
  make --no-print-directory -s -f "$SRC/Makefile.pipeline" DATASET="$1" BIN="$BIN" -j2 verify \
    REFERENCE="$2" > "$3" 2>&1 || status=$?
  return $status
}
REFERENCE=$WORK/vehicle/calibration.txtpb
mkdir -p "$WORK/vehicle"
cp "$DATA/out/calibration.txtpb" "$REFERENCE"
verify "$DATA" "$REFERENCE" "$WORK/verify.log" || { cat "$WORK/verify.log"; fail "verify: make failed"; }
cat "$WORK/verify.log"
grep -q "^verdict: HOLDS$" "$DATA/out/verify.txtpb" || fail "verify: the unbumped reference does not hold"
[ "$(grep -c "^sequences {" "$DATA/out/verify.txtpb")" = 2 ] || fail "verify: not two sequences"
grep -qE "^seq_1 +HOLDS" "$WORK/verify.log" && grep -qE "^seq_2 +HOLDS" "$WORK/verify.log" ||
  fail "verify: the table does not show both sequences holding"
grep -q '<section class="verify"' "$DATA/out/report.html" || fail "verify: no section on the page"
# Knocked: 2 deg of yaw (about the IMU's vertical z) and 3 cm along b-x.
"$SRC/bench/verify/bump_reference.sh" "$REFERENCE" "$WORK/vehicle/bumped.txtpb" 0 0 2 0.03 0 0 0
verify "$DATA" "$WORK/vehicle/bumped.txtpb" "$WORK/bumped.log" &&
  { cat "$WORK/bumped.log"; fail "verify: make succeeded with a bumped reference"; }
cat "$WORK/bumped.log"
grep -q "^verdict: MOVED$" "$DATA/out/verify.txtpb" || fail "verify: the bumped reference did not move"
for s in seq_1 seq_2; do
  grep -qE "^$s +MOVED" "$WORK/bumped.log" || fail "verify: $s did not move"
done
# The estimate minus the bumped reference: -2 deg about b-z, -3 cm along b-x.
grep -qE "seq_1: moved: rotation [0-9.]+ deg about b \(-?0\.0[0-9], -?0\.0[0-9], -(0\.99|1\.00)\)" \
  "$WORK/bumped.log" || fail "verify: the yaw is not named"
grep -qE "seq_1: moved: translation [0-9.]+ mm along b \(-(0\.99|1\.00), -?0\.[01][0-9], -?0\.[01][0-9]\)" \
  "$WORK/bumped.log" || fail "verify: the move along b-x is not named"
grep -q '<section class="verify"' "$DATA/out/report.html" || fail "verify: no section after MOVED"
cp "$DATA/out/report.html" "$WORK/report_moved.html"

# One bag and a rig in a folder is a dataset, and the rig needs no
# extrinsic: a first user's rig (topics, IMU height) without imu_from_lidar.
# make ends with the dataset calibration (that sequence's, with a reason
# saying there was no check between sequences) and the page; the starting
# extrinsic came from the motion alone, and the errors against the truth
# stay within the bounds above.
ONE=$WORK/one_bag
mkdir -p "$ONE/params"
sed '/^imu_from_lidar {/,/^}/d' "$DATA/rig.txtpb" > "$ONE/rig.txtpb"
! grep -q imu_from_lidar "$ONE/rig.txtpb" || fail "the rig still has imu_from_lidar"
cp -p "$DATA/seq_1.bag" "$DATA/seq_1.truth.txtpb" "$ONE/"
cp -p "$DATA/params/verify.txtpb" "$ONE/params/"
make --no-print-directory -s -f "$SRC/Makefile.pipeline" DATASET="$ONE" BIN="$BIN" -j2 \
  > "$WORK/one.log" 2>&1 || { tail -20 "$WORK/one.log"; fail "make on a dataset of one bag failed"; }
grep -q "guess_source: NONE" "$ONE/out/seq_1/rig.txtpb" || fail "one bag: the start was not from the motion"
grep -q "starting extrinsic: no guess" "$ONE/out/seq_1/calibration.txtpb" ||
  fail "one bag: the calibration does not say where its start came from"
# Without a lever-arm guess a short sequence may leave the plane's lever arm
# weak (a 20 s drive of this figure-eight: 4.8 cm off in y, sigma 3.1 cm):
# then the verdict is WEAK and names the translation, and only rotation, the
# vertical and tau keep the bounds above. (This 12 s one: OK, 0.028 deg,
# 0.13 / 0.15 / 0.00 cm, tau 0.203 ms.)
cat "$ONE/out/repeatability.txt"
plane_weak=0
grep -q "^verdict_reasons: \"translation along b .* weakly determined by the motion" "$ONE/out/seq_1/calibration.txtpb" && plane_weak=1
awk -F, -v plane_weak=$plane_weak 'function abs(v) { return v < 0 ? -v : v }
NR > 1 && $1 == "seq_1" {
  found = 1
  if ($9 == "" || $9 > 0.25 || abs($12) > 1 || abs($13) > 0.5 ||
      (!plane_weak && (abs($10) > 1 || abs($11) > 1))) {
    print "FAIL: no rig extrinsic: errors rot " $9 " deg, x " $10 " cm, y " $11 " cm, z " $12 " cm, tau " $13 " ms (plane weak: " plane_weak ")"
    bad = 1
  }
} END { exit bad || !found }' "$ONE/out/repeatability.csv" || fail "one bag without a rig extrinsic: errors too large"
for f in calibration.txtpb report.html repeatability.txt; do
  [ -s "$ONE/out/$f" ] || fail "one bag: no out/$f"
done
grep -qE "^verdict: (OK|WEAK)$" "$ONE/out/calibration.txtpb" || fail "one bag: dataset verdict"
grep -q "one sequence: no consistency check between sequences" "$ONE/out/calibration.txtpb" ||
  fail "one bag: the dataset calibration does not say it had one sequence"
verify "$ONE" "$REFERENCE" "$WORK/one_verify.log" || { cat "$WORK/one_verify.log"; fail "one bag: verify failed"; }
grep -q "^verdict: HOLDS$" "$ONE/out/verify.txtpb" || fail "one bag: the reference does not hold"

# Too little turning cannot decide the extrinsic: 3 s still, then 2 s (3 s)
# of driving off nearly straight; calibrate refuses the first (CANNOT_TELL
# with its reason), the second is calibrated with a yaw of sigma 0.5 deg
# (CANNOT_TELL naming the rotation about b-z); never HOLDS, exit 4.
for seconds in 5 6; do
  STRAIGHT=$WORK/straight_$seconds
  mkdir -p "$STRAIGHT"
  sed -E "s/^duration_s: .*/duration_s: $seconds/" \
    "$SRC/stages/simulate/scenarios/flat_vlp16_40s.txtpb" > "$WORK/straight_$seconds.txtpb"
  "$BIN/tiltcal_simulate" --params="$WORK/straight_$seconds.txtpb" --out_bag="$STRAIGHT/drive.bag" \
    --out_truth="$WORK/straight_truth.txtpb" --out_rig="$STRAIGHT/rig.txtpb" 2> /dev/null ||
    fail "straight $seconds s: simulate failed"
  verify "$STRAIGHT" "$REFERENCE" "$WORK/straight.log" &&
    { cat "$WORK/straight.log"; fail "straight $seconds s: make verify succeeded"; }
  grep -q "^verdict: CANNOT_TELL$" "$STRAIGHT/out/verify.txtpb" ||
    { cat "$WORK/straight.log"; fail "straight $seconds s: not CANNOT_TELL"; }
  grep -q "verify\] Error 4" "$WORK/straight.log" || fail "straight $seconds s: tiltcal_verify did not exit 4"
done
grep -qE "cannot be calibrated: (.*: )?the motion cannot decide the extrinsic rotation: too little turning" \
  "$WORK/straight_5/out/verify.txtpb" || fail "straight 5 s: calibrate's reason is not named"
# The 6 s drive is at the turning threshold: either the yaw is named weak or
# the starting extrinsic's search finds too little turning (it does, 0.016
# rad RMS per pair against 0.02); CANNOT_TELL names which.
grep -qE "cannot tell: a rotation about b \(-?0\.0[0-9], -?0\.0[0-9], 1\.00\) below|cannot be calibrated: .*too little turning" \
  "$WORK/straight_6/out/verify.txtpb" || fail "straight 6 s: neither the weak yaw nor the turning is named"

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
  grep -q 'Check against a stored calibration: <span class="verdict verdict-HOLDS">HOLDS' <<<"$dom" ||
    fail "one bag: the page does not show the check holding"
  dom=$(chromium --headless --no-sandbox --disable-gpu --no-first-run \
    --user-data-dir="$WORK/chromium" --virtual-time-budget=2000 \
    --dump-dom "file://$WORK/report_moved.html" 2> /dev/null) || fail "verify: chromium failed"
  grep -q 'Check against a stored calibration: <span class="verdict verdict-MOVED">MOVED' <<<"$dom" ||
    fail "verify: the page does not show the move"
  [ "$(grep -o '<td class="verdict-MOVED">MOVED</td>' <<<"$dom" | wc -l)" = 2 ] ||
    fail "verify: the page's table does not show both sequences moved"
  grep -q "seq_1: moved: rotation" <<<"$dom" || fail "verify: the page does not name the rotation"
else
  echo "chromium is not installed (scripts/setup.sh installs it): the one-bag page not opened"
fi
echo PASS
