#!/usr/bin/env bash
# Clock offsets and rig mistakes on the 40 s figure-eight
# (stages/simulate/scenarios/flat_vlp16_40s.txtpb), LiDAR + IMU only: for
# each case the scenario is edited, simulated, decoded and calibrated, and
# the script prints the errors against the simulator's truth (rotation deg,
# translation cm per axis of b, tau ms) with the wide-window facts of
# calibration.txtpb, or the calibrator's refusal (exit code and its line).
# Cases: tau = 12.5 ms (the scenario), 80 ms, 0.3 s, 2 s, 10 min (another
# clock domain: decode refuses); the rig's
# rotation off by 90 deg about the IMU's z (yaw) and by 180 deg about its x
# (an IMU upside down); the gyro in deg/s. Needs the simulator's rig_file
# rotation_error_in_imu_deg and faults { imu_gyro_unit } and a
# rig.time_offset_s beyond 1 s.
#
# Usage: bench/calibrate/run_clock_rig_bench.sh [--build_dir DIR]
#          [--scratch DIR] [CASE...]   (default every case)
set -euo pipefail

. "$(dirname "$0")/../common.sh"
bench_args "[CASE...]" "tau12ms tau80ms tau300ms tau2s tau10min yaw90 upside_down gyro_degps (default all)"
bench_parse "$@"
require_binaries tiltcal_simulate tiltcal_decode tiltcal_calibrate
CASES=(${BENCH_ARGS[@]+"${BENCH_ARGS[@]}"})
[ ${#CASES[@]} -eq 0 ] && CASES=(tau12ms tau80ms tau300ms tau2s tau10min yaw90 upside_down gyro_degps)
BASE="$REPO/stages/simulate/scenarios/flat_vlp16_40s.txtpb"

# Scenario of a case: the base with one edit (sed expression).
edit_for() {
  case "$1" in
    tau12ms) echo 's/^\(  time_offset_s:\).*/\1 0.0125/' ;;
    tau80ms) echo 's/^\(  time_offset_s:\).*/\1 0.08/' ;;
    tau300ms) echo 's/^\(  time_offset_s:\).*/\1 0.3/' ;;
    tau2s) echo 's/^\(  time_offset_s:\).*/\1 2.0/' ;;
    tau10min) echo 's/^\(  time_offset_s:\).*/\1 600/' ;;
    yaw90) echo 's/^\(  gravity_reference: ""\)/\1\n  rotation_error_in_imu_deg { z: 90 }/' ;;
    upside_down) echo 's/^\(  gravity_reference: ""\)/\1\n  rotation_error_in_imu_deg { x: 180 }/' ;;
    gyro_degps) echo 's/^\(num_threads: .*\)/\1\nfaults { imu_gyro_unit: DEGPS }/' ;;
    *) echo "unknown case $1" >&2; exit 2 ;;
  esac
}

printf '%-12s %5s %8s  %s\n' case exit wall_s result
for c in "${CASES[@]}"; do
  d="$SCRATCH/$c"
  mkdir -p "$d"
  sed "$(edit_for "$c")" "$BASE" > "$d/scenario.txtpb"
  "$BIN/tiltcal_simulate" --quiet --params="$d/scenario.txtpb" --out_bag="$d/s.bag" \
    --out_truth="$d/truth.txtpb" --out_rig="$d/rig.txtpb"
  rm -f "$d/imu.binpb" "$d/scans.binpb.lz4" "$d/calibration.txtpb"
  set +e
  "$BIN/tiltcal_decode" --bag="$d/s.bag" --rig="$d/rig.txtpb" --out_imu="$d/imu.binpb" \
    --out_scans="$d/scans.binpb.lz4" 2> "$d/decode.log"
  code=$?
  set -e
  rm -f "$d/s.bag"
  if [ $code -ne 0 ]; then
    printf '%-12s %5s %8s  decode: %s\n' "$c" "$code" "-" "$(tail -1 "$d/decode.log")"
    continue
  fi
  start=$(date +%s.%N)
  set +e
  "$BIN/tiltcal_calibrate" --imu="$d/imu.binpb" --scans="$d/scans.binpb.lz4" \
    --rig="$d/rig.txtpb" --out="$d/calibration.txtpb" 2> "$d/calibrate.log"
  code=$?
  set -e
  wall=$(echo "$(date +%s.%N) - $start" | bc)
  if [ $code -eq 0 ] || [ $code -eq 3 ]; then
    result=$(python3 - "$d" <<'PY'
import math, re, sys
d = sys.argv[1]
def read(path):
    text = re.sub(r'provenance \{.*?\n\}\n', '', open(path).read(), flags=re.S)
    block = text[text.index('imu_from_lidar {'):]
    rot, trans = block.split('translation {')[0], block.split('translation {')[1].split('}')[0]
    get = lambda s, k: float(re.search(r'\b' + k + r': (\S+)', s).group(1)) if re.search(r'\b' + k + r': (\S+)', s) else 0.0
    tau = re.search(r'^time_offset_s: (\S+)', text, re.M)
    verdict = re.search(r'^verdict: (\S+)', text, re.M)
    facts = {k: get(text, k) for k in ('coarse_time_offset_s', 'coarse_time_offset_correlation',
                                       'coarse_time_offset_second_peak_correlation',
                                       'gyro_to_lidar_rate_scale')}
    facts['verdict'] = verdict.group(1) if verdict else 'OK'
    return [get(rot, k) for k in 'wxyz'], [get(trans, k) for k in 'xyz'], float(tau.group(1)) if tau else 0.0, facts
qt, tt, taut, _ = read(d + '/truth.txtpb')
qe, te, taue, f = read(d + '/calibration.txtpb')
dot = abs(sum(a * b for a, b in zip(qt, qe)))
rot = 2 * math.degrees(math.acos(min(1.0, dot)))
cm = ' '.join('%+.2f' % ((a - b) * 100) for a, b in zip(te, tt))
print('%s: rotation %.4f deg, translation (%s) cm, tau %+.3f ms; coarse tau %.4f s (r %.3f, '
      'second %.3f, scale %.3f)' % (f['verdict'], rot, cm, (taue - taut) * 1e3, f['coarse_time_offset_s'],
      f['coarse_time_offset_correlation'], f['coarse_time_offset_second_peak_correlation'],
      f['gyro_to_lidar_rate_scale']))
PY
)
  else
    result=$(tail -1 "$d/calibrate.log")
  fi
  printf '%-12s %5s %8.1f  %s\n' "$c" "$code" "$wall" "$result"
done
