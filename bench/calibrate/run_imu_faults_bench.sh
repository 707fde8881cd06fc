#!/usr/bin/env bash
# The IMUs users have, measured: the demo's 40 s Husky-like sequence (IMU
# upside down), flat and tilted (8 deg pitch, 3 deg roll, g_f from the flat
# sequence of the same seed), with one fault per run, or all of them:
#   consumer        gyroscope and accelerometer scale errors drawn up to
#                   SCALE ppm and axis misalignments up to MIS deg per seed
#                   (SimTriadErrors); compared: imu_intrinsics AUTO / OFF
#   vibration       engine vibration while moving (SimImuVibration,
#                   WHILE_MOVING) of HZ, ACCEL m/s^2 and GYRO rad/s per axis;
#                   compared: imu_vibration AUTO / OFF
#   idle_vibration  the same, also during the static start (ALWAYS)
#   drift           the LiDAR clock DRIFT ppm fast against the IMU's
#                   (lidar_clock_drift_ppm; decode notes it); compared:
#                   time_offset_drift AUTO (rate estimated, with decode's
#                   rate as prior) / DATA (AUTO without that prior:
#                   use_decode_rate false) / OFF (one tau)
#   all             every fault at once: the faults block of
#                   stages/simulate/scenarios/faulty_vehicle_vlp16_40s.txtpb
#                   (scale errors up to 5000 ppm and misalignments up to
#                   0.5 deg drawn per seed, 25 Hz vibration from the static
#                   start on, the LiDAR clock 50 ppm fast, 2 % of the scans
#                   dropped, grass, rolling ground, four pedestrians; the
#                   fault flags below do not apply)
# Each sequence is calibrated by `make -f Makefile.pipeline` as a one-bag
# dataset with the simulator's rig, once with the defaults (AUTO) and once
# with the fault's params block OFF (all: the defaults only).
# Prints one row per seed, ground and mode: exit code, verdict, rotation
# (deg), translation per axis (mm) and tau (ms) errors against the truth,
# whether the intrinsics were estimated, the score, the gyro z scale and
# the accelerometer's x/y scales found against the truth's (ppm), whether
# the IMU was low-pass filtered (and thinned by m), seconds of make; the
# clock rate found (ppm, with its sigma; "-" when not estimated), tau's
# error against the truth at the first and the last scan (ms) and
# tiltcal_calibrate's own total (s); then the NEES of the AUTO runs
# (covariance_consistency.py).
#   bench/calibrate/run_imu_faults_bench.sh [--build_dir=DIR] [--scratch=DIR]
#       [--seeds=101,102,103] [--fault=consumer] [--scale_ppm=10000]
#       [--misalignment_deg=0.5] [--vibration_hz=37] [--vibration_accel=1.5]
#       [--vibration_gyro=0.05] [--drift_ppm=50] [--duration_s=40]
# e.g. bench/calibrate/run_imu_faults_bench.sh --fault=drift --seeds=101 --duration_s=160
set -euo pipefail
. "$(dirname "$0")/../common.sh"
SRC=$REPO
bench_flag --seeds SEEDS 101,102,103 "simulator seeds, comma separated"
bench_flag --fault FAULT consumer "consumer, vibration, idle_vibration, drift or all"
bench_flag --scale_ppm SCALE 10000 "largest scale error, ppm (consumer)"
bench_flag --misalignment_deg MIS 0.5 "largest axis misalignment, deg (consumer)"
bench_flag --vibration_hz HZ 37 "vibration frequency, Hz"
bench_flag --vibration_accel ACCEL 1.5 "vibration amplitude, m/s^2 per axis"
bench_flag --vibration_gyro GYRO 0.05 "vibration amplitude, rad/s per axis"
bench_flag --drift_ppm DRIFT 50 "LiDAR clock drift, ppm (drift)"
bench_flag --duration_s DURATION 40 "sequence length, s"
bench_parse "$@"
case "$FAULT" in
  consumer) BLOCK=imu_intrinsics ;;
  vibration|idle_vibration) BLOCK=imu_vibration ;;
  drift) BLOCK=time_offset_drift ;;
  all) BLOCK="" ;;
  *) echo "unknown fault $FAULT (see --help)" >&2; exit 2 ;;
esac
require_binaries tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate
PY=/usr/bin/python3

# scenario KIND SEED: the demo's Husky scenario with the fault.
scenario() {
  local kind=$1 seed=$2 pitch=0 roll=0
  [ "$kind" = tilted ] && { pitch=8; roll=3; }
  sed -E -e "s/^seed: .*/seed: $seed/" -e "s/^duration_s: .*/duration_s: $DURATION/" \
    -e "s/^ground_pitch_deg: .*/ground_pitch_deg: $pitch/" \
    -e "s/^ground_roll_deg: .*/ground_roll_deg: $roll/" \
    "$SRC/stages/simulate/scenarios/tilted_husky_vlp16.txtpb"
  echo "faults {"
  case "$FAULT" in
    consumer)
      echo "  gyro_intrinsics { scale_max_ppm: $SCALE misalignment_max_deg: $MIS }"
      echo "  accel_intrinsics { scale_max_ppm: $SCALE misalignment_max_deg: $MIS }" ;;
    vibration|idle_vibration)
      local when=WHILE_MOVING
      [ "$FAULT" = idle_vibration ] && when=ALWAYS
      echo "  imu_vibration { frequency_hz: $HZ accel_amplitude_mps2: $ACCEL"
      echo "    gyro_amplitude_radps: $GYRO when: $when }" ;;
    drift)
      echo "  lidar_clock_drift_ppm: $DRIFT" ;;
    all)
      sed -n '/^faults {/,/^}/{/^faults {/d;/^}/d;p}' \
        "$SRC/stages/simulate/scenarios/faulty_vehicle_vlp16_40s.txtpb" ;;
  esac
  echo "}"
}

# report CALIBRATION TRUTH: the row's numbers.
report() {
  "$PY" - "$1" "$2" <<'PYEOF'
import math, os, sys
sys.path.insert(0, os.path.join(os.environ['SRC'], 'bench/calibrate'))
from calibration_errors import parse
def first(d, *path):
    for k in path:
        if not isinstance(d, dict) or k not in d: return None
        d = d[k][0] if isinstance(d[k], list) else d[k]
    return d
cal = parse(open(sys.argv[1]).read())
truth = parse(open(sys.argv[2]).read())
def pose(d):
    t = first(d, 'imu_from_lidar')
    q = [float(first(t, 'rotation', k) or 0) for k in 'wxyz']
    r = [float(first(t, 'translation', k) or 0) for k in 'xyz']
    return q, r
(q1, r1), (q2, r2) = pose(cal), pose(truth)
d = abs(sum(a * b for a, b in zip(q1, q2)))
rot = 2 * math.degrees(math.acos(min(1.0, d)))
tau = (float(first(cal, 'time_offset_s') or 0) - float(first(truth, 'time_offset_s') or 0)) * 1e3
k = first(cal, 'imu_intrinsics') or {}
est = first(k, 'estimated') == 'true'
score = float(first(k, 'score_chi2') or 0)
def scale(d, triad, axis):
    return float(first(d, triad, 'scale_ppm', axis) or 0)
gz = scale(k, 'gyro', 'z'); tgz = scale(truth, 'gyro_intrinsics', 'z')
ax = scale(k, 'accel', 'x'); tax = scale(truth, 'accel_intrinsics', 'x')
ay = scale(k, 'accel', 'y'); tay = scale(truth, 'accel_intrinsics', 'y')
v = first(cal, 'imu_vibration') or {}
filtered = 'm=%d' % int(float(first(v, 'decimation'))) if first(v, 'filtered') == 'true' else 'no'
# The clock drift: rate and sigma, and tau at the first / last scan against
# the truth's scans (true_stamp - stamp) there.
dr = first(cal, 'time_offset_drift') or {}
rate = ('%+.2f±%.2f' % (float(first(dr, 'rate_ppm') or 0), float(first(dr, 'rate_sigma_ppm') or 0))
        if first(dr, 'estimated') == 'true' else '-')
scans = truth.get('scans', [])
def true_tau(s):
    return (int(first(s, 'true_stamp_ns')) - int(first(s, 'stamp_ns'))) * 1e-9
ends = '- -'
if scans and dr:
    ends = '%+.3f %+.3f' % (
        (float(first(dr, 'time_offset_start_s') or 0) - true_tau(scans[0])) * 1e3,
        (float(first(dr, 'time_offset_end_s') or 0) - true_tau(scans[-1])) * 1e3)
total = next((float(first(t, 'seconds')) for t in cal.get('timings', [])
              if first(t, 'phase') == 'total'), 0.0)
print('%.3f  %6.1f %6.1f %6.1f  %6.2f  %-3s %8.0f  %6.0f/%6.0f  %6.0f/%6.0f  %6.0f/%6.0f  %-4s  %s  %s  %.0f' % (
    rot, *[(a - b) * 1e3 for a, b in zip(r1, r2)], tau, 'yes' if est else 'no', score,
    gz, tgz, ax, tax, ay, tay, filtered, rate, ends, total))
PYEOF
}

# run NAME SCENARIO_BAG MODE [GRAVITY_REFERENCE]
run() {
  local name=$1 bag=$2 mode=$3 ref=${4:-}
  local d=$SCRATCH/$name
  rm -rf "$d"; mkdir -p "$d/params"
  cp "$SCRATCH/$bag.bag" "$d/seq.bag"
  sed '/^gravity_reference:/d' "$SCRATCH/$bag.rig.txtpb" > "$d/rig.txtpb"
  [ -n "$ref" ] && echo "gravity_reference: \"$ref\"" >> "$d/rig.txtpb"
  local defaults=$SRC/stages/calibrate/default_params.txtpb
  case $mode in
    AUTO) cp "$defaults" "$d/params/calibrate.txtpb" ;;
    DATA) sed -E "/^$BLOCK \{/,/^\}/ s/^  use_decode_rate: true$/  use_decode_rate: false/" \
      "$defaults" > "$d/params/calibrate.txtpb" ;;
    *) sed -E "/^$BLOCK \{/,/^\}/ s/^  mode: AUTO$/  mode: $mode/" \
      "$defaults" > "$d/params/calibrate.txtpb" ;;
  esac
  local start=$SECONDS rc=0
  make -s -f "$SRC/Makefile.pipeline" DATASET="$d" BIN="$BIN" > "$d/make.log" 2>&1 || rc=$?
  local cal=$d/out/seq/calibration.txtpb
  [ -f "$cal" ] || cal=$d/out/seq/calibration.suspect.txtpb
  if [ -f "$cal" ]; then
    printf '%-5s %-7s %-5s rc %d  %-8s %s  %3d s\n' "${name%%_*}" "${bag%%.*}" "$mode" "$rc" \
      "$(sed -n 's/^verdict: //p' "$cal")" "$(report "$cal" "$SCRATCH/$bag.truth.txtpb")" \
      $((SECONDS - start))
  else
    printf '%-5s %-7s %-5s rc %d  no calibration: %s\n' "${name%%_*}" "${bag%%.*}" "$mode" "$rc" \
      "$(grep -m1 -E 'error|Error|refus' "$d/make.log" | cut -c1-160)"
  fi
}

export SRC
if [ -n "$BLOCK" ]; then echo "fault $FAULT; mode: $BLOCK.mode"; else echo "fault $FAULT; defaults"; fi
echo "seed  ground  mode  exit  verdict  rot_deg  dx_mm  dy_mm  dz_mm  tau_ms  est  score  gyro_z/truth  acc_x/truth  acc_y/truth  filtered  rate_ppm  tau_start/end_err_ms  calibrate_s  make"
for seed in ${SEEDS//,/ }; do
  for kind in flat tilted; do
    scenario $kind "$seed" > "$SCRATCH/$kind.$seed.scenario.txtpb"
    "$BIN/tiltcal_simulate" --params="$SCRATCH/$kind.$seed.scenario.txtpb" \
      --out_bag="$SCRATCH/$kind.$seed.bag" --out_truth="$SCRATCH/$kind.$seed.truth.txtpb" \
      --out_rig="$SCRATCH/$kind.$seed.rig.txtpb" 2> /dev/null
  done
  case "$FAULT" in
    drift) MODES="AUTO DATA OFF" ;;
    all) MODES=AUTO ;;
    *) MODES="AUTO OFF" ;;
  esac
  for mode in $MODES; do
    run "${seed}_flat_$mode" "flat.$seed" $mode
    run "${seed}_tilted_$mode" "tilted.$seed" $mode "../${seed}_flat_AUTO"
  done
done

# The covariance's honesty over the AUTO runs (covariance_consistency.py):
# each run's NEES of the 7-vector and the mean's 95 % band for that many.
pairs=""
for seed in ${SEEDS//,/ }; do
  for kind in flat tilted; do
    cal=$SCRATCH/${seed}_${kind}_AUTO/out/seq/calibration.txtpb
    [ -f "$cal" ] && pairs="$pairs $cal:$SCRATCH/$kind.$seed.truth.txtpb"
  done
done
[ -n "$pairs" ] && "$PY" "$SRC/bench/calibrate/covariance_consistency.py" $pairs
