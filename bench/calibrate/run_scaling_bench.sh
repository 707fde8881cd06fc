#!/usr/bin/env bash
# Scaling and anchor comparison of tiltcal_calibrate (docs/design.md §13).
# For each duration (default 20 40 80 160 s) it simulates one sequence of
# the scenario (default: the 10 x 5 m VLP-16 figure-eight,
# stages/simulate/scenarios/flat_vlp16_40s.txtpb, with duration_s replaced),
# runs decode -> ground -> gravity once, then tiltcal_calibrate of this
# build and of an anchor build (e.g. main's) on the same inputs, alternating
# which runs first, each under GNU time -v. It prints per run: wall, cpu
# (user + sys), peak resident memory, the odometry and solve phases (from
# calibration.txtpb), wall / duration, and the errors against the truth;
# then per binary the exponent b of a log-log fit wall = a duration^b
# (1 = linear) and the anchor / this ratios, and plots the time and the
# peak memory per second of data against the duration into
# <scratch>/scaling.png (kept with --keep or --scratch DIR). The machine
# load (uptime) is
# printed before and after: the machine is shared, so compare the ratios of
# one run, not absolute times across runs.
#
# Usage: bench/calibrate/run_scaling_bench.sh [options]
# Ground residuals are off (LiDAR + IMU only), as in run_calibrate_bench.sh.
set -euo pipefail

. "$(dirname "$0")/../common.sh"
bench_flag --anchor_bin ANCHOR_BIN "" "the anchor's bin/ directory (default: none, this build only)"
bench_flag --durations DURATIONS "20 40 80 160" "sequence durations, s"
bench_flag --scenario SCENARIO "$REPO/stages/simulate/scenarios/flat_vlp16_40s.txtpb" "simulate params"
bench_flag --seed SEED "" "simulator seed (default: the scenario's)"
bench_flag --params PARAMS "$REPO/stages/calibrate/default_params.txtpb" "calibrate params of this build"
bench_flag --anchor_params ANCHOR_PARAMS "" "calibrate params of the anchor (default: --params)"
bench_flag --threads THREADS 2 "num_threads of the calibrator"
bench_parse "$@"
[ -n "$ANCHOR_PARAMS" ] || ANCHOR_PARAMS=$PARAMS
. "$REPO/bench/calibrate/simulated_inputs.sh"
require_binaries tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate
require_anchor "$ANCHOR_BIN"

echo "load before: $(uptime)"
RESULTS="$SCRATCH/results.tsv"
: > "$RESULTS"
round=0
for d in $DURATIONS; do
  w="$SCRATCH/d$d"
  simulate_inputs "$BIN" "$REPO" "$SCENARIO" "$w" "$SEED" "$d"
  calibrate_params "$PARAMS" "$w/params_this.txtpb" "$THREADS"
  calibrate_params "$ANCHOR_PARAMS" "$w/params_anchor.txtpb" "$THREADS"
  labels="this"
  if [ -n "$ANCHOR_BIN" ]; then
    if [ $((round % 2)) -eq 0 ]; then labels="anchor this"; else labels="this anchor"; fi
  fi
  for label in $labels; do
    if [ "$label" = this ]; then
      run_calibrate this "$BIN" "$w/params_this.txtpb" "$w"
    else
      run_calibrate anchor "$ANCHOR_BIN" "$w/params_anchor.txtpb" "$w"
    fi
    printf '%s\t%s\t%s\n' "$d" "$label" "$w" >> "$RESULTS"
  done
  round=$((round + 1))
done
echo "load after:  $(uptime)"
# Debian's python3 has matplotlib for the plot (the first python3 on PATH
# may not).
PYTHON=/usr/bin/python3
[ -x "$PYTHON" ] || PYTHON=python3
"$PYTHON" "$REPO/bench/calibrate/scaling_report.py" "$RESULTS" --plot "$SCRATCH/scaling.png"
[ "$BENCH_SCRATCH_REMOVED" = 0 ] ||
  echo "(the scratch folder is removed now: --keep or --scratch DIR keeps the plot)"
