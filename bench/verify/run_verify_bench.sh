#!/usr/bin/env bash
# How small a bump tiltcal_verify detects on a 40 s sequence, and how often
# it cries wolf on unbumped ones (stages/verify/README.md, "Sensitivity").
#
# 1. The reference: a dataset of --reference_seeds (default 201-204) of the
#    scenario (default the 40 s VLP-16 figure-eight, flat_vlp16_40s.txtpb,
#    with the pipeline's defaults: ground residuals on) through
#    Makefile.pipeline dataset-calibration: its out/calibration.txtpb is the
#    stored calibration, as a vehicle's earlier recordings would give it.
# 2. False alarms: --seeds (default 1-20) of the same scenario through
#    decode, ground and gravity (make gravity), then tiltcal_verify of all of
#    them against the reference: every unbumped sequence should HOLD.
# 3. Sensitivity: the reference bumped (bump_reference.sh) about each axis of
#    the IMU (--rotations_deg), along each (--translations_m) and in tau
#    (--time_offsets_s), one size at a time, and tiltcal_verify of the first
#    --bump_seeds sequences against it. A bump is detected on a sequence when
#    its verdict is MOVED and the difference of the bumped group points the
#    right way (its largest component the bumped axis, with the opposite
#    sign: estimate - reference).
# verify_report.py prints both tables and the smallest moves each unbumped
# sequence reports it would detect (detectable_*, median and max).
#
# Usage: bench/verify/run_verify_bench.sh [options]
# Pass --scratch DIR to keep the work and reuse it in the next run.
# Runs everything under nice -n 10 (a shared machine).
set -euo pipefail

. "$(dirname "$0")/../common.sh"
bench_flag --scenario SCENARIO "$REPO/stages/simulate/scenarios/flat_vlp16_40s.txtpb" "simulate params"
bench_flag --seeds SEEDS "$(seq -s ' ' 1 20)" "unbumped sequences"
bench_flag --reference_seeds REFERENCE_SEEDS "201 202 203 204" "sequences of the reference"
bench_flag --bump_seeds BUMP_SEEDS 3 "how many of --seeds are checked against each bump"
bench_flag --rotations_deg ROTATIONS "0.1 0.2 0.3" "bump sizes about each axis"
bench_flag --translations_m TRANSLATIONS "0.005 0.01 0.02" "bump sizes along each axis"
bench_flag --time_offsets_s TIME_OFFSETS "0.0005 0.001 0.002" "tau bumps"
bench_parse "$@"
require_binaries tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate \
  tiltcal_dataset_calibration tiltcal_verify
NICE=(nice -n 10)

# simulate_dataset DIR SEEDS: one bag per seed (s<seed>.bag) and the rig.
simulate_dataset() {
  local dir=$1 seed first=1 rig
  mkdir -p "$dir"
  for seed in $2; do
    rig=()
    [ "$first" = 1 ] && rig=(--out_rig="$dir/rig.txtpb")
    first=0
    [ -s "$dir/s$seed.bag" ] && [ -s "$dir/rig.txtpb" ] && continue
    sed -E "s/^seed: .*/seed: $seed/" "$SCENARIO" > "$SCRATCH/scenario_$seed.txtpb"
    "${NICE[@]}" "$BIN/tiltcal_simulate" --quiet --params="$SCRATCH/scenario_$seed.txtpb" \
      --out_bag="$dir/s$seed.bag" --out_truth="$dir/s$seed.truth.txtpb" "${rig[@]}"
  done
}

echo "== reference: seeds $REFERENCE_SEEDS" >&2
simulate_dataset "$SCRATCH/reference" "$REFERENCE_SEEDS"
"${NICE[@]}" make --no-print-directory -s -f "$REPO/Makefile.pipeline" DATASET="$SCRATCH/reference" \
  BIN="$BIN" dataset-calibration
REFERENCE=$SCRATCH/reference/out/calibration.txtpb

echo "== unbumped: seeds $SEEDS" >&2
CHECK=$SCRATCH/check
simulate_dataset "$CHECK" "$SEEDS"
# The check's sequences use the reference's rig (the same vehicle).
cp "$SCRATCH/reference/rig.txtpb" "$CHECK/rig.txtpb"
"${NICE[@]}" make --no-print-directory -s -f "$REPO/Makefile.pipeline" DATASET="$CHECK" \
  BIN="$BIN" -j2 gravity
dirs=()
for seed in $SEEDS; do dirs+=("$CHECK/out/s$seed"); done
run_verify() {  # run_verify REFERENCE OUT DIRS...: tiltcal_verify, exit 0/3/4 accepted
  local reference=$1 out=$2 status=0
  shift 2
  "${NICE[@]}" "$BIN/tiltcal_verify" --reference="$reference" --rig="$CHECK/rig.txtpb" \
    --out="$out" "$@" > "$out.table" 2> "$out.log" || status=$?
  case $status in 0|3|4) ;; *) cat "$out.log" >&2; exit 1 ;; esac
}
mkdir -p "$SCRATCH/results"
run_verify "$REFERENCE" "$SCRATCH/results/unbumped.txtpb" "${dirs[@]}"
cat "$SCRATCH/results/unbumped.txtpb.table"

echo "== bumps on the first $BUMP_SEEDS sequences" >&2
bump_dirs=("${dirs[@]:0:$BUMP_SEEDS}")
bump() {  # bump NAME RX RY RZ DX DY DZ DTAU
  local name=$1
  shift
  [ -s "$SCRATCH/results/bump_$name.txtpb" ] && return
  "$REPO/bench/verify/bump_reference.sh" "$REFERENCE" "$SCRATCH/results/reference_$name.txtpb" "$@"
  run_verify "$SCRATCH/results/reference_$name.txtpb" "$SCRATCH/results/bump_$name.txtpb" \
    "${bump_dirs[@]}"
  echo "  $name: $(sed -n 's/^verdict: //p' "$SCRATCH/results/bump_$name.txtpb")" >&2
}
for v in $ROTATIONS; do
  bump "rotation_x_$v" "$v" 0 0 0 0 0 0
  bump "rotation_y_$v" 0 "$v" 0 0 0 0 0
  bump "rotation_z_$v" 0 0 "$v" 0 0 0 0
done
for v in $TRANSLATIONS; do
  bump "translation_x_$v" 0 0 0 "$v" 0 0 0
  bump "translation_y_$v" 0 0 0 0 "$v" 0 0
  bump "translation_z_$v" 0 0 0 0 0 "$v" 0
done
for v in $TIME_OFFSETS; do bump "tau_$v" 0 0 0 0 0 0 "$v"; done
/usr/bin/python3 "$REPO/bench/verify/verify_report.py" --results="$SCRATCH/results"
