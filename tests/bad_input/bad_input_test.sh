#!/usr/bin/env bash
# Every binary fed bad files in each of its input slots: missing, empty, a
# directory, garbage, truncated, NaN / Inf / huge values. Each case must end
# with exit 1, exactly one output line naming the bad file, no output file
# and no temporary (*.tmp*) left behind. Valid inputs for the other slots
# come from a 3 s simulated sequence run through decode, ground and gravity.
#   bad_input_test.sh BUILD_DIR
set -uo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${1:?usage: bad_input_test.sh BUILD_DIR}" && pwd)/bin
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
GOOD=$WORK/good
BAD=$WORK/bad
OUT=$WORK/out
mkdir -p "$GOOD" "$BAD" "$OUT"
die() { echo "FAIL: $*" >&2; exit 1; }

# ---- valid inputs ----
source "$(dirname "$0")/valid_inputs.sh"
make_valid_inputs "$BIN" "$SRC" "$GOOD" "$WORK/log" || die "the valid inputs"
# A calibration answer as calibrate writes it (the truth's extrinsic and τ).
grep -A12 "^imu_from_lidar" "$GOOD/truth.txtpb" | sed -n '1,/^}/p' > "$GOOD/calibration.txtpb"
grep "^time_offset_s" "$GOOD/truth.txtpb" >> "$GOOD/calibration.txtpb"
echo 'gravity_in_world { z: -9.81 }' >> "$GOOD/calibration.txtpb"

# ---- bad files ----
: > "$BAD/empty"
mkdir "$BAD/dir"
head -c 3000 /dev/urandom > "$BAD/garbage"
printf 'TILTCAL1\x05\x0a\x03abc' > "$BAD/bad_header.binpb"
truncate_half() { head -c $(($(stat -c %s "$1") / 2)) "$1" > "$2"; }
truncate_half "$GOOD/seq.bag" "$BAD/truncated.bag"
truncate_half "$GOOD/imu.binpb" "$BAD/truncated_imu.binpb"
truncate_half "$GOOD/scans.binpb.lz4" "$BAD/truncated_scans.binpb.lz4"
truncate_half "$GOOD/ground.binpb" "$BAD/truncated_ground.binpb"
sed -E '/^  translation \{/,/^  \}/ s/^(    x:).*/\1 nan/' "$GOOD/rig.txtpb" > "$BAD/nan_rig.txtpb"
sed -E '/^  rotation \{/,/^  \}/ s/^(    w:).*/\1 1e300/' "$GOOD/rig.txtpb" > "$BAD/huge_rig.txtpb"
grep -q "^    x: nan$" "$BAD/nan_rig.txtpb" && grep -q "^    w: 1e300$" "$BAD/huge_rig.txtpb" ||
  { echo "the rig's translation x or rotation w not found" >&2; exit 1; }
sed -E 's/^imu_height_m:.*/imu_height_m: -1/' "$GOOD/rig.txtpb" > "$BAD/negative_height_rig.txtpb"
grep -q "^imu_height_m: -1$" "$BAD/negative_height_rig.txtpb" || { echo "no imu_height_m in the rig" >&2; exit 1; }
echo "imu_from_lidar { rotation { w: nan } }" > "$BAD/nan_calibration.txtpb"
echo "has_gravity_flat: true gravity_flat_in_imu { z: inf }" > "$BAD/inf_gravity.txtpb"
# params_with STAGE FIELD VALUE FILE: the stage's defaults with the (one) line
# of FIELD given VALUE instead (a field given twice is refused on its own).
params_with() {
  sed -E "s/^([[:space:]]*$2:).*/\1 $3/" "$SRC/stages/$1/default_params.txtpb" > "$4"
  [ "$(grep -cE "^[[:space:]]*$2: $3\$" "$4")" = 1 ] || { echo "params_with: no one $2 in $1" >&2; exit 1; }
}
params_with decode start_offset_s 1e300 "$BAD/huge_decode_params.txtpb"
params_with decode min_range_m nan "$BAD/nan_decode_params.txtpb"
params_with ground window_s inf "$BAD/inf_ground_params.txtpb"
params_with gravity hop_s nan "$BAD/nan_gravity_params.txtpb"
params_with calibrate gyro_bias_segment_s 1e-300 "$BAD/tiny_segment_params.txtpb"
params_with calibrate knot_spacing_s nan "$BAD/nan_calibrate_params.txtpb"
sed -E 's/^duration_s:.*/duration_s: 1e300/' "$GOOD/scenario.txtpb" > "$BAD/huge_scenario.txtpb"
grep -q "^duration_s: 1e300$" "$BAD/huge_scenario.txtpb" || { echo "no duration_s in the scenario" >&2; exit 1; }

failures=0
cases=0
# expect_failure FILE COMMAND...: exit 1, one line naming FILE, $OUT empty,
# no temporary in the input directories either. With STREAMING=1 (inspect
# printing the records it could read before a truncation) the error must
# be the last line instead of the only one.
expect_failure() {
  local file=$1
  shift
  cases=$((cases + 1))
  rm -rf "$OUT" && mkdir -p "$OUT"
  local output rc
  output=$("$@" 2>&1)
  rc=$?
  local lines
  lines=$(printf '%s\n' "$output" | grep -c .)
  [ "${STREAMING:-0}" = 1 ] && { output=$(printf '%s\n' "$output" | tail -1); lines=1; }
  local problem=""
  if [ "$rc" != 1 ]; then problem="exit $rc (expected 1)"
  elif [ "$lines" != 1 ]; then problem="$lines output lines (expected 1)"
  elif ! printf '%s' "$output" | grep -qF -- "$file"; then problem="the line does not name $file"
  elif [ -n "$(ls -A "$OUT")" ]; then problem="left in the output directory: $(ls -A "$OUT")"
  elif [[ "$(ls "$GOOD" "$BAD")" == *.tmp* ]]; then problem="a temporary file was left"
  fi
  if [ -n "$problem" ]; then
    failures=$((failures + 1))
    echo "FAIL: ${*##*/}"
    echo "      $problem; output: $output"
  fi
}

# Each input slot of a stage gets every generic bad file.
generic_bad_files() { echo "$WORK/missing" "$BAD/empty" "$BAD/dir" "$BAD/garbage"; }

# ---- tiltcal_decode ----
decode() {  # decode BAG RIG PARAMS
  "$BIN/tiltcal_decode" --bag="$1" --rig="$2" ${3:+--params="$3"} --out_imu="$OUT/imu.binpb" \
    --out_scans="$OUT/scans.binpb.lz4"
}
for f in $(generic_bad_files) "$BAD/truncated.bag" "$BAD/truncated_imu.binpb"; do
  expect_failure "$f" decode "$f" "$GOOD/rig.txtpb" ""
done
for f in $(generic_bad_files) "$BAD/nan_rig.txtpb" "$BAD/huge_rig.txtpb" \
    "$BAD/negative_height_rig.txtpb"; do
  expect_failure "$f" decode "$GOOD/seq.bag" "$f" ""
done
for f in $(generic_bad_files) "$BAD/huge_decode_params.txtpb" "$BAD/nan_decode_params.txtpb"; do
  expect_failure "$f" decode "$GOOD/seq.bag" "$GOOD/rig.txtpb" "$f"
done
expect_failure "$WORK/no_dir/imu.binpb" "$BIN/tiltcal_decode" --bag="$GOOD/seq.bag" \
  --out_imu="$WORK/no_dir/imu.binpb" --out_scans="$OUT/scans.binpb.lz4"

# ---- tiltcal_initial_extrinsic ----
initial_extrinsic() {  # initial_extrinsic IMU SCANS RIG PARAMS
  "$BIN/tiltcal_initial_extrinsic" --imu="$1" --scans="$2" --rig="$3" ${4:+--params="$4"} \
    --out="$OUT/rig.txtpb"
}
for f in $(generic_bad_files) "$BAD/bad_header.binpb" "$BAD/truncated_imu.binpb" \
    "$GOOD/scans.binpb.lz4"; do
  expect_failure "$f" initial_extrinsic "$f" "$GOOD/scans.binpb.lz4" "$GOOD/rig.txtpb" ""
done
for f in $(generic_bad_files) "$BAD/truncated_scans.binpb.lz4" "$GOOD/imu.binpb"; do
  expect_failure "$f" initial_extrinsic "$GOOD/imu.binpb" "$f" "$GOOD/rig.txtpb" ""
done
for f in $(generic_bad_files) "$BAD/nan_rig.txtpb" "$BAD/huge_rig.txtpb" \
    "$BAD/negative_height_rig.txtpb"; do
  expect_failure "$f" initial_extrinsic "$GOOD/imu.binpb" "$GOOD/scans.binpb.lz4" "$f" ""
done

# ---- tiltcal_ground ----
ground() {  # ground IMU SCANS RIG PARAMS
  "$BIN/tiltcal_ground" --imu="$1" --scans="$2" --rig="$3" ${4:+--params="$4"} \
    --out_ground="$OUT/ground.binpb"
}
for f in $(generic_bad_files) "$BAD/bad_header.binpb" "$BAD/truncated_imu.binpb" \
    "$GOOD/scans.binpb.lz4"; do
  expect_failure "$f" ground "$f" "$GOOD/scans.binpb.lz4" "$GOOD/rig.txtpb" ""
done
for f in $(generic_bad_files) "$BAD/truncated_scans.binpb.lz4" "$GOOD/imu.binpb"; do
  expect_failure "$f" ground "$GOOD/imu.binpb" "$f" "$GOOD/rig.txtpb" ""
done
for f in $(generic_bad_files) "$BAD/nan_rig.txtpb" "$BAD/huge_rig.txtpb" \
    "$BAD/negative_height_rig.txtpb"; do
  expect_failure "$f" ground "$GOOD/imu.binpb" "$GOOD/scans.binpb.lz4" "$f" ""
done
for f in $(generic_bad_files) "$BAD/inf_ground_params.txtpb"; do
  expect_failure "$f" ground "$GOOD/imu.binpb" "$GOOD/scans.binpb.lz4" "$GOOD/rig.txtpb" "$f"
done

# ---- tiltcal_gravity ----
gravity() {  # gravity IMU GROUND RIG CALIBRATION PARAMS
  "$BIN/tiltcal_gravity" --imu="$1" --ground="$2" --rig="$3" ${4:+--calibration="$4"} \
    ${5:+--params="$5"} --out="$OUT/gravity.txtpb"
}
for f in $(generic_bad_files) "$BAD/truncated_imu.binpb"; do
  expect_failure "$f" gravity "$f" "$GOOD/ground.binpb" "$GOOD/rig.txtpb" "" ""
done
for f in $(generic_bad_files) "$BAD/truncated_ground.binpb" "$GOOD/imu.binpb"; do
  expect_failure "$f" gravity "$GOOD/imu.binpb" "$f" "$GOOD/rig.txtpb" "" ""
done
for f in $(generic_bad_files) "$BAD/nan_rig.txtpb"; do
  expect_failure "$f" gravity "$GOOD/imu.binpb" "$GOOD/ground.binpb" "$f" "" ""
done
for f in $(generic_bad_files) "$BAD/nan_calibration.txtpb" "$GOOD/truth.txtpb"; do
  expect_failure "$f" gravity "$GOOD/imu.binpb" "$GOOD/ground.binpb" "$GOOD/rig.txtpb" "$f" ""
done
for f in $(generic_bad_files) "$BAD/nan_gravity_params.txtpb"; do
  expect_failure "$f" gravity "$GOOD/imu.binpb" "$GOOD/ground.binpb" "$GOOD/rig.txtpb" "" "$f"
done

# ---- tiltcal_calibrate ----
calibrate() {  # calibrate IMU SCANS GROUND GRAVITY RIG PARAMS
  "$BIN/tiltcal_calibrate" --imu="$1" --scans="$2" --ground="$3" --gravity="$4" --rig="$5" \
    ${6:+--params="$6"} --out="$OUT/calibration.txtpb"
}
G=("$GOOD/imu.binpb" "$GOOD/scans.binpb.lz4" "$GOOD/ground.binpb" "$GOOD/gravity.txtpb"
   "$GOOD/rig.txtpb" "")
for slot in 0 1 2 3 4 5; do
  extra=()
  case $slot in
    0) extra=("$BAD/truncated_imu.binpb") ;;
    1) extra=("$BAD/truncated_scans.binpb.lz4" "$GOOD/imu.binpb") ;;
    2) extra=("$BAD/truncated_ground.binpb") ;;
    3) extra=("$BAD/inf_gravity.txtpb") ;;
    4) extra=("$BAD/nan_rig.txtpb" "$BAD/huge_rig.txtpb") ;;
    5) extra=("$BAD/tiny_segment_params.txtpb" "$BAD/nan_calibrate_params.txtpb") ;;
  esac
  for f in $(generic_bad_files) "${extra[@]}"; do
    args=("${G[@]}")
    args[$slot]=$f
    expect_failure "$f" calibrate "${args[@]}"
  done
done

# ---- tiltcal_report ----
for f in "$BAD/empty" "$BAD/dir" "$BAD/garbage" "$BAD/nan_calibration.txtpb"; do
  for name in calibration.txtpb truth.txtpb; do
    rm -rf "$WORK/seq" && mkdir -p "$WORK/seq"
    cp "$GOOD/calibration.txtpb" "$WORK/seq/calibration.txtpb"
    rm -rf "$WORK/seq/$name" && cp -r "$f" "$WORK/seq/$name"
    expect_failure "$WORK/seq/$name" "$BIN/tiltcal_report" --out="$OUT/repeatability.txt" \
      "$WORK/seq"
  done
done

# The maps the page draws (both must exist for the snapshots; the other one
# is a valid PCD without points).
for f in "$BAD/empty" "$BAD/dir" "$BAD/garbage"; do
  for name in map_rig.pcd map_calibrated.pcd; do
    rm -rf "$WORK/seq" && mkdir -p "$WORK/seq"
    cp "$GOOD/calibration.txtpb" "$WORK/seq/calibration.txtpb"
    for map in map_rig.pcd map_calibrated.pcd; do
      printf 'FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 0\nDATA binary\n' > "$WORK/seq/$map"
    done
    rm -rf "$WORK/seq/$name" && cp -r "$f" "$WORK/seq/$name"
    expect_failure "$WORK/seq/$name" "$BIN/tiltcal_report" --out="$OUT/repeatability.txt" \
      --out_html="$OUT/report.html" "$WORK/seq"
  done
done

# ---- tiltcal_inspect ----
for cmd in info cat csv; do
  for f in $(generic_bad_files) "$BAD/bad_header.binpb"; do
    expect_failure "$f" "$BIN/tiltcal_inspect" "$cmd" "$f"
  done
  for f in "$BAD/truncated_imu.binpb" "$BAD/truncated_scans.binpb.lz4"; do
    STREAMING=1 expect_failure "$f" "$BIN/tiltcal_inspect" "$cmd" "$f"
  done
done
for f in $(generic_bad_files); do
  expect_failure "$f" "$BIN/tiltcal_inspect" info --bag="$f"
done
for f in $(generic_bad_files) "$BAD/truncated_scans.binpb.lz4"; do
  # The last scan lies past the truncation.
  expect_failure "$f" "$BIN/tiltcal_inspect" pcd "$f" --record=29 --out="$OUT/scan.pcd"
done

# ---- tiltcal_simulate ----
for f in $(generic_bad_files) "$BAD/huge_scenario.txtpb"; do
  expect_failure "$f" "$BIN/tiltcal_simulate" --params="$f" --out_bag="$OUT/seq.bag" \
    --out_truth="$OUT/truth.txtpb"
done

echo "$cases bad-input cases, $failures failures"
[ "$failures" = 0 ]
