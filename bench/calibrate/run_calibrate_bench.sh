#!/usr/bin/env bash
# tiltcal_calibrate benchmark (docs/design.md §13): simulates a
# sequence (default: the 60 s, 200 Hz, VLP-16 flat-ground Husky sequence
# stages/simulate/scenarios/flat_vlp16.txtpb), runs decode -> ground ->
# gravity -> calibrate, and prints
#   - wall and cpu time per stage and the calibrator's own phases
#     (from calibration.txtpb: init, odometry, map, association, solve, ...);
#   - seconds per LM iteration and the problem size (knots, residuals by kind);
#   - the errors against the simulator's truth: rotation (deg), translation
#     per axis of b and in the plane of motion (cm), tau (ms).
# Anchor measured in the same run: the sequence length (x_realtime =
# duration_s / calibrate wall). Targets: whole stage <= 60 s wall on 2 cores,
# <= 0.25 s per LM iteration.
#
# Usage: bench/calibrate/run_calibrate_bench.sh [options] (below); the
# stage binaries are built into --build_dir (Release) when it has none.
set -euo pipefail

BENCH_BUILD_DIR=build-bench
. "$(dirname "$0")/../common.sh"
bench_flag --scenario SCENARIO "$REPO/stages/simulate/scenarios/flat_vlp16.txtpb" "simulate params"
bench_flag --model MODEL "" "override the LiDAR model (VLP_16, VLP_32C, OS1_32)"
bench_flag --seed SEED "" "override the simulator seed (noise and world)"
bench_flag --params PARAMS "$REPO/stages/calibrate/default_params.txtpb" "calibrate params"
bench_flag --threads THREADS 2 "num_threads of the calibrator"
bench_flag --ground GROUND off "off (LiDAR + IMU only, as the accuracy targets) or auto (ground residuals as the params say; g_f comes with the simulated rig)"
bench_parse "$@"

TARGETS="tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate"
if [ ! -x "$BUILD_DIR/bin/tiltcal_calibrate" ]; then
  cmake -S "$REPO" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$BUILD_DIR" --target $TARGETS -j2
fi
require_binaries $TARGETS
W="$SCRATCH"

scenario="$W/scenario.txtpb"
sed -e 's/write_gravity_flat: false/write_gravity_flat: true/' \
  -e 's/gravity_reference: ".*"/gravity_reference: ""/' "$SCENARIO" > "$scenario"
[ -n "$MODEL" ] && sed -i -e "s/^  model: .*/  model: $MODEL/" "$scenario"
[ -n "$SEED" ] && sed -i -e "s/^seed: .*/seed: $SEED/" "$scenario"
sed -e "s/^num_threads: .*/num_threads: $THREADS/" "$PARAMS" > "$W/calibrate_params.txtpb"
if [ "$GROUND" = off ]; then
  sed -i -E -e "/^  (flat|dist|incl|up) \{/ s/mode: (AUTO|ON)/mode: OFF/" "$W/calibrate_params.txtpb"
fi

now() { date +%s.%N; }
declare -A WALL CPU
run() {  # name, command...
  local name=$1; shift
  local t0 t1
  t0=$(now)
  /usr/bin/time -f "%U %S" -o "$W/time_$name.txt" "$@" 2> "$W/log_$name.txt" || {
    echo "run_calibrate_bench: $name failed:" >&2; tail -5 "$W/log_$name.txt" >&2; exit 1; }
  t1=$(now)
  WALL[$name]=$(echo "$t1 - $t0" | bc -l)
  CPU[$name]=$(awk '{print $1 + $2}' "$W/time_$name.txt")
}

run simulate "$BIN/tiltcal_simulate" --params="$scenario" --out_bag="$W/seq.bag" \
  --out_truth="$W/truth.txtpb" --out_rig="$W/rig.txtpb"
run decode "$BIN/tiltcal_decode" --bag="$W/seq.bag" --params="$REPO/stages/decode/default_params.txtpb" \
  --rig="$W/rig.txtpb" --out_imu="$W/imu.binpb" --out_scans="$W/scans.binpb.lz4"
run ground "$BIN/tiltcal_ground" --imu="$W/imu.binpb" --scans="$W/scans.binpb.lz4" --rig="$W/rig.txtpb" \
  --params="$REPO/stages/ground/default_params.txtpb" --out_ground="$W/ground.binpb"
run gravity "$BIN/tiltcal_gravity" --imu="$W/imu.binpb" --ground="$W/ground.binpb" --rig="$W/rig.txtpb" \
  --params="$REPO/stages/gravity/default_params.txtpb" --out="$W/gravity.txtpb"
run calibrate "$BIN/tiltcal_calibrate" --imu="$W/imu.binpb" --scans="$W/scans.binpb.lz4" \
  --ground="$W/ground.binpb" --gravity="$W/gravity.txtpb" --rig="$W/rig.txtpb" \
  --params="$W/calibrate_params.txtpb" --out="$W/calibration.txtpb"

echo "scenario: $SCENARIO ${MODEL:+(model $MODEL)}${SEED:+(seed $SEED)}, calibrator threads: $THREADS, ground residuals: $GROUND, nproc: $(nproc), load: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-10s %9s %9s\n' stage wall_s cpu_s
for s in simulate decode ground gravity calibrate; do
  printf '%-10s %9.2f %9.2f\n' "$s" "${WALL[$s]}" "${CPU[$s]}"
done
duration_s=$(sed -nE 's/^duration_s: *([0-9.]+).*/\1/p' "$scenario")
python3 "$REPO/bench/calibrate/calibration_errors.py" "$W/calibration.txtpb" "$W/truth.txtpb" \
  "$W/rig.txtpb" "${WALL[calibrate]}" "$duration_s"
echo "stderr of tiltcal_calibrate: $W/log_calibrate.txt"
