# Sourced, after bench/common.sh, by the calibrate benchmarks
# (run_scaling_bench.sh, run_seeds_bench.sh, run_mid360_seeds.sh): the calibrator's inputs for one simulated sequence,
# its params with the thread count set and the ground residuals off (LiDAR +
# IMU only, the setting the accuracy targets are stated for), the check of
# the anchor's binary, one calibrate run under GNU time, and the steal counter.

# simulate_inputs BIN REPO SCENARIO WORKDIR [SEED [DURATION_S]]: simulates the
# scenario (gravity_flat written, no gravity reference; seed and duration
# replaced when given) and runs decode -> ground -> gravity into WORKDIR
# (scenario.txtpb, truth.txtpb, rig.txtpb, imu.binpb, scans.binpb.lz4,
# ground.binpb, gravity.txtpb; the bag is removed).
simulate_inputs() {
  local bin=$1 repo=$2 scenario=$3 w=$4 seed=${5:-} duration=${6:-}
  mkdir -p "$w"
  sed -e 's/write_gravity_flat: false/write_gravity_flat: true/' \
      -e 's/gravity_reference: ".*"/gravity_reference: ""/' "$scenario" > "$w/scenario.txtpb"
  [ -n "$seed" ] && sed -i -e "s/^seed: .*/seed: $seed/" "$w/scenario.txtpb"
  [ -n "$duration" ] && sed -i -e "s/^duration_s: .*/duration_s: $duration/" "$w/scenario.txtpb"
  "$bin/tiltcal_simulate" --params="$w/scenario.txtpb" --out_bag="$w/seq.bag" \
    --out_truth="$w/truth.txtpb" --out_rig="$w/rig.txtpb" 2> "$w/log_simulate.txt"
  "$bin/tiltcal_decode" --bag="$w/seq.bag" --params="$repo/stages/decode/default_params.txtpb" \
    --rig="$w/rig.txtpb" --out_imu="$w/imu.binpb" --out_scans="$w/scans.binpb.lz4" 2> "$w/log_decode.txt"
  rm -f "$w/seq.bag"
  "$bin/tiltcal_ground" --imu="$w/imu.binpb" --scans="$w/scans.binpb.lz4" --rig="$w/rig.txtpb" \
    --params="$repo/stages/ground/default_params.txtpb" --out_ground="$w/ground.binpb" 2> "$w/log_ground.txt"
  "$bin/tiltcal_gravity" --imu="$w/imu.binpb" --ground="$w/ground.binpb" --rig="$w/rig.txtpb" \
    --params="$repo/stages/gravity/default_params.txtpb" --out="$w/gravity.txtpb" 2> "$w/log_gravity.txt"
}

# calibrate_params IN OUT THREADS [GROUND]: IN with num_threads THREADS and
# every ground residual OFF, or as IN sets them when GROUND is 1.
calibrate_params() {
  # Only the ground residuals' lines: imu_intrinsics has a mode too.
  local ground_off="/^  (flat|dist|incl|up) \{/ s/mode: (AUTO|ON)/mode: OFF/"
  [ "${4:-0}" = 1 ] && ground_off=""
  sed -E -e "s/^num_threads: .*/num_threads: $3/" -e "$ground_off" "$1" > "$2"
}

# steal_ticks: CPU time the hypervisor gave to other guests since boot, in
# USER_HZ ticks (/proc/stat, field 9 of the cpu line).
steal_ticks() {
  awk '/^cpu / {print $9}' /proc/stat
}

# require_anchor ANCHOR_BIN: its tiltcal_calibrate, when ANCHOR_BIN is not
# empty; exits 2 naming it when missing.
require_anchor() {
  [ -z "$1" ] || [ -x "$1/tiltcal_calibrate" ] ||
    bench_die "$1/tiltcal_calibrate (--anchor_bin) missing"
}

# run_calibrate NAME BIN PARAMS WORKDIR: BIN/tiltcal_calibrate on WORKDIR's
# inputs under GNU time -v, writing time_NAME.txt, calibration_NAME.txtpb and
# log_NAME.txt there; exits 1 with the log's end when it fails.
run_calibrate() {
  local name=$1 bin=$2 params=$3 w=$4
  /usr/bin/time -v -o "$w/time_$name.txt" "$bin/tiltcal_calibrate" --imu="$w/imu.binpb" \
    --scans="$w/scans.binpb.lz4" --ground="$w/ground.binpb" --gravity="$w/gravity.txtpb" \
    --rig="$w/rig.txtpb" --params="$params" --out="$w/calibration_$name.txtpb" \
    2> "$w/log_$name.txt" || {
      echo "$(basename "$0"): calibrate $name of $w failed:" >&2; tail -3 "$w/log_$name.txt" >&2; exit 1; }
}
