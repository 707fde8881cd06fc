#!/usr/bin/env bash
# One calibration per dataset, measured against the simulator's truth:
# a flat dataset (3 sequences) gives g_f through its calibrations
# (gravity-reference), a tilted dataset (5 sequences, 8 deg pitch, 3 deg
# roll, different seeds) is calibrated sequence by sequence and jointly
# (dataset-calibration). Then a sixth tilted sequence whose LiDAR was bumped
# on its mount (the extrinsic 0.5 deg off about the IMU's y) joins the
# dataset: it must be left out, and the joint value must not move.
# Prints bench/dataset/dataset_errors.py for both, and the wall time of the
# joint step against one sequence's calibration.
#
# Bags in --scratch DIR are reused by the next run with the same DIR.
#
# Usage: bench/dataset/run_dataset_bench.sh [--build_dir DIR] [--scratch DIR]
#          [--duration_s S]
set -euo pipefail
. "$(dirname "$0")/../common.sh"
bench_flag --duration_s DURATION_S 40 "sequence length, s"
bench_parse "$@"
require_binaries tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate \
  tiltcal_gravity_reference tiltcal_dataset_calibration
WORK=$SCRATCH
FLAT=$WORK/husky_flat
TILTED=$WORK/husky_incline
mkdir -p "$FLAT" "$TILTED"

simulate() {  # base dataset name seed heading [extra sed expression]
  local base=$1 dir=$2 name=$3 seed=$4 heading=$5 extra=${6:-}
  [ -s "$dir/$name.bag" ] && return 0
  sed -E -e "s/^seed: .*/seed: $seed/" -e "s/^duration_s: .*/duration_s: $DURATION_S/" \
    -e "s/^([[:space:]]*heading_deg:).*/\1 $heading/" ${extra:+-e "$extra"} \
    "$REPO/stages/simulate/scenarios/$base.txtpb" > "$dir/$name.scenario"
  local rig=""
  [ -s "$dir/rig.txtpb" ] || rig="--out_rig=$dir/rig.txtpb"
  "$BIN/tiltcal_simulate" --quiet --params="$dir/$name.scenario" --out_bag="$dir/$name.bag" \
    --out_truth="$dir/$name.truth.txtpb" $rig
}

for i in 1 2 3; do simulate flat_vlp16 "$FLAT" "flat_$i" $((100 * i + 3)) $((20 + 37 * i)); done
for i in 1 2 3 4 5; do
  simulate tilted_husky_vlp16 "$TILTED" "tilted_$i" $((100 * i + 5)) $((20 + 37 * i))
done
sed -i -E 's#^gravity_reference:.*#gravity_reference: "../husky_flat"#' "$TILTED/rig.txtpb"
grep -q gravity_reference "$TILTED/rig.txtpb" ||
  echo 'gravity_reference: "../husky_flat"' >> "$TILTED/rig.txtpb"

MAKE=(make --no-print-directory -s -f "$REPO/Makefile.pipeline" BIN="$BIN" -j2)
"${MAKE[@]}" DATASET="$TILTED" calibrate > "$WORK/make_tilted.log" 2>&1
start=$(date +%s.%N)
"${MAKE[@]}" DATASET="$TILTED" dataset-calibration 2> "$WORK/joint.log"
joint_s=$(echo "$(date +%s.%N) - $start" | bc)
echo "== five tilted sequences (g_f from the flat dataset's calibrations)"
grep -h "flat_calibrations_max_angle_deg\|gravity_flat_source" "$FLAT/out/gravity_reference.txtpb"
/usr/bin/python3 "$REPO/bench/dataset/dataset_errors.py" "$TILTED"
one_wall=$(python3 - "$TILTED/out/tilted_1/calibration.txtpb" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
print(sum(float(x) for x in re.findall(r'timings \{\s*phase: "[^"]*"\s*seconds: (\S+)', text)))
PY
)
echo "joint step: ${joint_s} s wall; one sequence's calibration: ${one_wall} s (sum of its phases)"

echo "== with a sixth sequence whose LiDAR was bumped by 0.5 deg"
simulate tilted_husky_vlp16 "$TILTED" "tilted_bumped" 905 200 \
  's/^(  lidar_rotation_in_imu_deg \{ x: 180 y:) 0 /\1 0.5 /'
"${MAKE[@]}" DATASET="$TILTED" dataset-calibration 2> "$WORK/joint_bumped.log" || true
grep -A20 "^sequence" "$WORK/joint_bumped.log" | head -12
/usr/bin/python3 "$REPO/bench/dataset/dataset_errors.py" "$TILTED"
