#!/usr/bin/env bash
# Covariance consistency of tiltcal_calibrate (stages/calibrate/README.md):
# simulates N flat sequences (stages/simulate/scenarios/flat_vlp16.txtpb cut
# to DURATION s on a 10 x 5 m loop at 1.2 m/s, seeds 40+i, headings 30 i deg,
# one rig), runs Makefile.pipeline with the default params, and prints the
# NEES and z-scores of the errors against the truth in units of the reported
# covariance (bench/calibrate/covariance_consistency.py).
# Sequences in <scratch>/flat are reused when the scratch is.
#   bench/calibrate/run_covariance_consistency.sh [--build_dir DIR]
#       [--sequences N] [--duration S] [--scratch DIR]
set -euo pipefail
. "$(dirname "$0")/../common.sh"
bench_flag --sequences N 6 "how many sequences"
bench_flag --duration DURATION 20 "sequence length, s"
bench_parse "$@"
require_binaries tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate
SRC=$REPO
WORK=$SCRATCH
DATA=$WORK/flat
mkdir -p "$DATA"
for i in $(seq 1 "$N"); do
  [ -s "$DATA/seq_$i.bag" ] && continue
  sed -E -e "s/^seed: .*/seed: $((40 + i))/" -e "s/^duration_s: .*/duration_s: $DURATION/" \
    -e "s/^([[:space:]]*heading_deg:).*/\1 $((30 * i))/" \
    -e "s/^(  length_m:).*/\1 10/" -e "s/^(  width_m:).*/\1 5/" -e "s/^(  speed_mps:).*/\1 1.2/" \
    "$SRC/stages/simulate/scenarios/flat_vlp16.txtpb" > "$WORK/seq_$i.txtpb"
  rig=""
  [ "$i" = 1 ] && rig="--out_rig=$DATA/rig.txtpb"
  "$BIN/tiltcal_simulate" --params="$WORK/seq_$i.txtpb" --out_bag="$DATA/seq_$i.bag" \
    --out_truth="$DATA/seq_$i.truth.txtpb" $rig 2> /dev/null
done
# -k: a SUSPECT sequence (calibration.suspect.txtpb) is reported too.
make --no-print-directory -s -k -f "$SRC/Makefile.pipeline" DATASET="$DATA" BIN="$BIN" -j2 \
  calibrate > "$WORK/make.log" 2>&1 || true
pairs=()
for i in $(seq 1 "$N"); do
  for f in calibration.txtpb calibration.suspect.txtpb; do
    [ -s "$DATA/out/seq_$i/$f" ] && pairs+=("$DATA/out/seq_$i/$f:$DATA/seq_$i.truth.txtpb")
  done
done
python3 "$SRC/bench/calibrate/covariance_consistency.py" "${pairs[@]}"
