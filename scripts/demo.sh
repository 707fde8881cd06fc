#!/usr/bin/env bash
# The one-command demo: installs what is missing, builds, simulates a
# flat-ground dataset (3 sequences) and a tilted one (5 sequences, 8 deg
# pitch and 3 deg roll) with the Husky-like rig, runs Makefile.pipeline on
# both with -j2, and prints the repeatability tables with the errors against
# the simulation truth, and where the plots are.
#
#   scripts/demo.sh                      # datasets in datasets/demo/
#   DEMO_DIR=/tmp/demo DEMO_DURATION_S=30 scripts/demo.sh
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
DEMO_DIR=${DEMO_DIR:-$ROOT/datasets/demo}
DURATION_S=${DEMO_DURATION_S:-40}
FLAT=$DEMO_DIR/husky_flat
TILTED=$DEMO_DIR/husky_incline
BIN=$ROOT/build/bin
declare -a TIMINGS=()

phase() {  # phase "<name>" command...: runs and records the wall time
  local name=$1
  shift
  local start=$SECONDS
  echo "== $name" >&2
  "$@"
  TIMINGS+=("$(printf '%-34s %5d s' "$name" $((SECONDS - start)))")
}

# One scenario file per sequence: the dataset's scenario with its own seed,
# heading and duration.
write_scenario() {  # base_scenario seed heading_deg out_file
  sed -E -e "s/^seed: .*/seed: $2/" -e "s/^duration_s: .*/duration_s: $DURATION_S/" \
    -e "s/^([[:space:]]*heading_deg:).*/\1 $3/" "$1" > "$4"
}

simulate_dataset() {  # base_scenario dataset_dir prefix count
  local base=$1 dir=$2 prefix=$3 count=$4
  rm -rf "$dir"
  mkdir -p "$dir/scenarios"
  for i in $(seq 1 "$count"); do
    write_scenario "$base" $((100 * i + count)) $((20 + 37 * i)) "$dir/scenarios/${prefix}_$i.txtpb"
  done
  # Two sequences at a time; the first also writes the dataset's rig file.
  for i in $(seq 1 "$count"); do
    local rig_flag=""
    [ "$i" = 1 ] && rig_flag="--out_rig=$dir/rig.txtpb"
    echo "$BIN/tiltcal_simulate --params=$dir/scenarios/${prefix}_$i.txtpb" \
      "--out_bag=$dir/${prefix}_$i.bag --out_truth=$dir/${prefix}_$i.truth.txtpb $rig_flag"
  done | xargs -P 2 -I{} sh -c '{}'
}

build_tools() {
  scripts/setup.sh
  if [ ! -f build/build.ninja ]; then
    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
  fi
  cmake --build build -j "$(nproc)" --target tiltcal_simulate tiltcal_decode tiltcal_ground \
    tiltcal_gravity tiltcal_gravity_reference tiltcal_calibrate tiltcal_dataset_calibration \
    tiltcal_report tiltcal_inspect tiltcal_export
}

phase "setup and build" build_tools
phase "simulate flat dataset (3 x ${DURATION_S} s)" \
  simulate_dataset stages/simulate/scenarios/flat_vlp16.txtpb "$FLAT" flat 3
phase "simulate tilted dataset (5 x ${DURATION_S} s)" \
  simulate_dataset stages/simulate/scenarios/tilted_husky_vlp16.txtpb "$TILTED" tilted 5
# The tilted dataset takes its flat-ground gravity g_f from the flat dataset's
# calibrations (out/gravity_reference.txtpb, made by the tilted dataset's make).
sed -i -E 's#^gravity_reference:.*#gravity_reference: "../husky_flat"#' "$TILTED/rig.txtpb"
grep -q gravity_reference "$TILTED/rig.txtpb" ||
  echo 'gravity_reference: "../husky_flat"' >> "$TILTED/rig.txtpb"

phase "pipeline, flat dataset (-j2)" make -s -f Makefile.pipeline DATASET="$FLAT" -j2
phase "pipeline, tilted dataset (-j2)" make -s -f Makefile.pipeline DATASET="$TILTED" -j2

echo
for dataset in "$FLAT" "$TILTED"; do
  cat "$dataset/out/repeatability.txt"
  echo
done
echo "Report pages (open in a browser: calibration, exports, wall snapshots, residual plots):" \
  "$FLAT/out/report.html $TILTED/out/report.html" | sed "s#$ROOT/##g"
echo "One calibration per dataset (the joint row above): $TILTED/out/calibration.txtpb;" \
  "for FAST-LIO: build/bin/tiltcal_export --calibration=$TILTED/out/calibration.txtpb" \
  "--format=fast_lio" | sed "s#$ROOT/##g"
echo "Plots:"
ls -1 "$FLAT"/out/*.png "$TILTED"/out/*.png "$FLAT"/out/*/*.png "$TILTED"/out/*/*.png 2>/dev/null |
  sed "s#^$ROOT/##; s#^#  #"
echo
echo "Time per part:"
printf '  %s\n' "${TIMINGS[@]}"
