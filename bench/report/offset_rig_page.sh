#!/usr/bin/env bash
# The before/after evidence of the report page on a simulated dataset whose
# rig file is off by 2.0 deg and 6.8 cm: two 30 s sequences of the
# flat_vlp16 scenario (seeds 1 and 2) with the rig file's rotation off by
# rotation_error_in_imu_deg { x: 1.0 y: -1.0 z: 1.414214 } and its
# translation by translation_error_m { x: 0.05 y: -0.045 z: 0.02 }, run
# through Makefile.pipeline; prints per sequence the map sharpness with the
# rig's extrinsic and with the estimate (calibration.txtpb) and where the
# page is. About 5 minutes on 2 cores.
#
# The dataset is <scratch>/dataset (made afresh), or DATASET_DIR when given.
# The scratch folder is kept (the page is the result): its path is printed.
#
# Usage: bench/report/offset_rig_page.sh [--build_dir DIR] [--scratch DIR] [DATASET_DIR]
set -euo pipefail
. "$(dirname "$0")/../common.sh"
bench_args "[DATASET_DIR]" "the dataset folder, made afresh (default <scratch>/dataset)"
KEEP=1
bench_parse "$@"
require_binaries tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate \
  tiltcal_dataset_calibration tiltcal_report
DATASET=${BENCH_ARGS[0]:-$SCRATCH/dataset}
cd "$REPO"
rm -rf "$DATASET"
mkdir -p "$DATASET/scenarios"
for seed in 1 2; do
  sed -E -e "s/^seed: .*/seed: $seed/" -e "s/^duration_s: .*/duration_s: 30/" \
    -e 's/^(  rotation_error_deg).*/\1 { x: 0 y: 0 z: 0 }\n  rotation_error_in_imu_deg { x: 1.0 y: -1.0 z: 1.414214 }/' \
    -e 's/^(  translation_error_m).*/\1 { x: 0.05 y: -0.045 z: 0.02 }/' \
    stages/simulate/scenarios/flat_vlp16.txtpb > "$DATASET/scenarios/offset_$seed.txtpb"
  rig_flag=""
  [ "$seed" = 1 ] && rig_flag="--out_rig=$DATASET/rig.txtpb"
  "$BIN/tiltcal_simulate" --quiet --params="$DATASET/scenarios/offset_$seed.txtpb" \
    --out_bag="$DATASET/offset_$seed.bag" --out_truth="$DATASET/offset_$seed.truth.txtpb" $rig_flag
done
make -s -f Makefile.pipeline DATASET="$DATASET" BIN="$BIN" -j2 report
echo
# Thickness over the voxels planar in both maps (common), surfels of each map.
printf '%-10s %22s %22s %7s %8s %10s\n' sequence "rig: thickness/surfels" "estimate: thick/surf" common ratio verdict
for seq in offset_1 offset_2; do
  f=$(ls "$DATASET/out/$seq"/calibration*.txtpb | head -1)
  /usr/bin/python3 - "$f" "$seq" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
def block(name):
    m = re.search(name + r" \{([^}]*)\}", text)
    t = float(re.search(r"median_thickness_m: ([-0-9.e]+)", m.group(1)).group(1))
    n = int(re.search(r"planar_surfels: (\d+)", m.group(1)).group(1))
    c = int(re.search(r"common_surfels: (\d+)", m.group(1)).group(1))
    return t, n, c
rig, est = block("map_sharpness_rig"), block("map_sharpness_estimate")
verdict = re.search(r"^verdict: (\w+)", text, re.M).group(1)
print(f"{sys.argv[2]:<10} {1e3*rig[0]:12.2f} mm {rig[1]:5d} {1e3*est[0]:12.2f} mm {est[1]:5d}"
      f" {est[2]:7d} {est[0]/rig[0]:8.3f} {verdict:>10}")
PY
done
echo
echo "page: $DATASET/out/report.html ($(du -h "$DATASET/out/report.html" | cut -f1))"
