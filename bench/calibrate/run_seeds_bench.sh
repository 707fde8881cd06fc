#!/usr/bin/env bash
# Accuracy and speed of tiltcal_calibrate over many simulated seeds of one
# scenario, against an anchor build on the same inputs (docs/design.md §13).
# A single sequence's error wanders by about its σ with the path the outer
# loop takes (docs/decisions.md), so a change is
# judged on the RMS and the maximum over seeds, not on one run.
#
# For each seed (default 1-16) it simulates the scenario (default the 40 s
# VLP-16 figure-eight, flat_vlp16_40s.txtpb) and runs decode -> ground ->
# gravity once into <scratch>/s<seed> (reused, with --scratch DIR, while
# the scenario file is the same); then, --passes times, tiltcal_calibrate of this build
# and of the anchor (--anchor_bin) on each seed, alternating which runs
# first, each under GNU time -v, with the CPU time the hypervisor gave to
# other guests meanwhile (steal, /proc/stat): on a shared VM a run that lost
# seconds to steal is slow for that reason alone. seeds_report.py prints
# every run and, per binary, the mean wall and CPU, the runs over
# --wall_goal seconds, the odometry, the errors against the truth (RMS and
# max over the seeds) and the anchor / this ratios.
#
# Usage: bench/calibrate/run_seeds_bench.sh [options]
# Ground residuals are off (LiDAR + IMU only) unless --ground_residuals, as
# in run_calibrate_bench.sh.
set -euo pipefail

. "$(dirname "$0")/../common.sh"
bench_flag --anchor_bin ANCHOR_BIN "" "the anchor's bin/ directory (default: none, this build only; this build when only --anchor_params is given)"
bench_flag --seeds SEEDS "$(seq -s ' ' 1 16)" "simulator seeds"
bench_flag --passes PASSES 1 "runs of every binary on every seed"
bench_flag --scenario SCENARIO "$REPO/stages/simulate/scenarios/flat_vlp16_40s.txtpb" "simulate params"
bench_flag --params PARAMS "$REPO/stages/calibrate/default_params.txtpb" "calibrate params of this build"
bench_flag --anchor_params ANCHOR_PARAMS "" "calibrate params of the anchor (default: --params)"
bench_flag --threads THREADS 2 "num_threads of the calibrator"
bench_flag --wall_goal WALL_GOAL 10 "the wall time, s, the report counts runs over"
bench_switch --ground_residuals GROUND_RESIDUALS "keep the ground residuals as the params set them"
bench_parse "$@"
# Params alone compared: the anchor is this build with --anchor_params.
[ -n "$ANCHOR_PARAMS" ] && [ -z "$ANCHOR_BIN" ] && ANCHOR_BIN=$BIN
[ -n "$ANCHOR_PARAMS" ] || ANCHOR_PARAMS=$PARAMS
. "$REPO/bench/calibrate/simulated_inputs.sh"
require_binaries tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate
require_anchor "$ANCHOR_BIN"
calibrate_params "$PARAMS" "$SCRATCH/params_this.txtpb" "$THREADS" "$GROUND_RESIDUALS"
calibrate_params "$ANCHOR_PARAMS" "$SCRATCH/params_anchor.txtpb" "$THREADS" "$GROUND_RESIDUALS"

for seed in $SEEDS; do
  w="$SCRATCH/s$seed"
  if [ -f "$w/inputs.done" ] && cmp -s "$w/inputs.done" "$SCENARIO"; then continue; fi
  echo "run_seeds_bench: simulating seed $seed" >&2
  rm -f "$w/inputs.done"
  simulate_inputs "$BIN" "$REPO" "$SCENARIO" "$w" "$seed"
  cp "$SCENARIO" "$w/inputs.done"
done

# One calibrate run with the steal time meanwhile, appended to the results.
run_and_record() {  # label, bin dir, params, work dir, pass
  local before after
  before=$(steal_ticks)
  run_calibrate "$1_$5" "$2" "$3" "$4"
  after=$(steal_ticks)
  printf '%s\t%s\t%s\t%s\t%s\n' "$5" "$1" "$4" "$((after - before))" "$(getconf CLK_TCK)" >> "$RESULTS"
}

echo "load before: $(uptime)"
RESULTS="$SCRATCH/results.tsv"
: > "$RESULTS"
round=0
for pass in $(seq 1 "$PASSES"); do
  for seed in $SEEDS; do
    labels="this"
    if [ -n "$ANCHOR_BIN" ]; then
      if [ $((round % 2)) -eq 0 ]; then labels="anchor this"; else labels="this anchor"; fi
    fi
    for label in $labels; do
      if [ "$label" = this ]; then
        run_and_record this "$BIN" "$SCRATCH/params_this.txtpb" "$SCRATCH/s$seed" "$pass"
      else
        run_and_record anchor "$ANCHOR_BIN" "$SCRATCH/params_anchor.txtpb" "$SCRATCH/s$seed" "$pass"
      fi
    done
    round=$((round + 1))
  done
done
echo "load after:  $(uptime)"
python3 "$REPO/bench/calibrate/seeds_report.py" "$RESULTS" --wall_goal "$WALL_GOAL"
