#!/usr/bin/env bash
# Accuracy and speed of tiltcal_calibrate over many simulated seeds of one
# scenario, against an anchor build on the same inputs (docs/design.md §13).
# A single sequence's error wanders by about its σ with the path the outer
# loop takes (docs/decisions.md), so a change is
# judged on the RMS and the maximum over seeds, not on one run.
#
# For each seed (default 1-16) it simulates the scenario (default the 40 s
# VLP-16 figure-eight, flat_vlp16_40s.txtpb) and runs decode -> ground ->
# gravity once into <scratch>/s<seed> (kept and reused while the scenario
# file is the same); then, --passes times, tiltcal_calibrate of this build
# and of the anchor (--anchor_bin) on each seed, alternating which runs
# first, each under GNU time -v, with the CPU time the hypervisor gave to
# other guests meanwhile (steal, /proc/stat): on a shared VM a run that lost
# seconds to steal is slow for that reason alone. seeds_report.py prints
# every run and, per binary, the mean wall and CPU, the runs over
# --wall_goal seconds, the odometry, the errors against the truth (RMS and
# max over the seeds) and the anchor / this ratios.
#
# Usage: bench/calibrate/run_seeds_bench.sh [options]
#   --build_dir DIR    this build (default <repo>/build)
#   --anchor_bin DIR   the anchor's bin/ directory (default: none, this build
#                      only; this build when only --anchor_params is given)
#   --seeds "N.."      simulator seeds (default "1 2 ... 16")
#   --passes N         runs of every binary on every seed (default 1)
#   --scenario FILE    simulate params (default flat_vlp16_40s.txtpb)
#   --params FILE      calibrate params of this build (default its default_params.txtpb)
#   --anchor_params F  calibrate params of the anchor (default: --params)
#   --threads N        num_threads of the calibrator (default 2)
#   --wall_goal S      the wall time the report counts runs over (default 10)
#   --scratch DIR      work directory (default /tmp/tiltcal_seeds_bench)
#   --ground_residuals keep the ground residuals as the params set them
# Ground residuals are off (LiDAR + IMU only) unless --ground_residuals, as
# in run_calibrate_bench.sh.
set -euo pipefail

REPO=$(cd "$(dirname "$0")/../.." && pwd)
BUILD_DIR="$REPO/build"
ANCHOR_BIN=""
SEEDS=$(seq -s ' ' 1 16)
PASSES=1
SCENARIO="$REPO/stages/simulate/scenarios/flat_vlp16_40s.txtpb"
PARAMS="$REPO/stages/calibrate/default_params.txtpb"
ANCHOR_PARAMS=""
THREADS=2
WALL_GOAL=10
SCRATCH=/tmp/tiltcal_seeds_bench
GROUND_RESIDUALS=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build_dir) BUILD_DIR=$2; shift 2 ;;
    --anchor_bin) ANCHOR_BIN=$2; shift 2 ;;
    --seeds) SEEDS=$2; shift 2 ;;
    --passes) PASSES=$2; shift 2 ;;
    --scenario) SCENARIO=$2; shift 2 ;;
    --params) PARAMS=$2; shift 2 ;;
    --anchor_params) ANCHOR_PARAMS=$2; shift 2 ;;
    --threads) THREADS=$2; shift 2 ;;
    --wall_goal) WALL_GOAL=$2; shift 2 ;;
    --scratch) SCRATCH=$2; shift 2 ;;
    --ground_residuals) GROUND_RESIDUALS=1; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "run_seeds_bench: unknown argument $1" >&2; exit 2 ;;
  esac
done
BIN="$BUILD_DIR/bin"
# Params alone compared: the anchor is this build with --anchor_params.
[ -n "$ANCHOR_PARAMS" ] && [ -z "$ANCHOR_BIN" ] && ANCHOR_BIN=$BIN
[ -n "$ANCHOR_PARAMS" ] || ANCHOR_PARAMS=$PARAMS
. "$REPO/bench/calibrate/simulated_inputs.sh"
require_binaries "$BIN" "$ANCHOR_BIN"
mkdir -p "$SCRATCH"
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
