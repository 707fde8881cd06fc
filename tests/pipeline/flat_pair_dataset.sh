# Sourced by the pipeline tests (bash): simulate_flat_pair BIN SRC WORK DATA
# writes two flat 12 s sequences (the flat_vlp16 scenario in a 10 x 5 m
# figure-eight at 1.2 m/s, seeds 41 and 42, headings 30 and 60 deg) into
# DATA as seq_1.bag, seq_2.bag with their truths, and the rig DATA/rig.txtpb;
# the scenario files go to WORK.
simulate_flat_pair() {
  local bin=$1 src=$2 work=$3 data=$4 i rig
  mkdir -p "$data"
  for i in 1 2; do
    sed -E -e "s/^seed: .*/seed: $((40 + i))/" -e "s/^duration_s: .*/duration_s: 12/" \
      -e "s/^([[:space:]]*heading_deg:).*/\1 $((30 * i))/" \
      -e "s/^(  length_m:).*/\1 10/" -e "s/^(  width_m:).*/\1 5/" -e "s/^(  speed_mps:).*/\1 1.2/" \
      "$src/stages/simulate/scenarios/flat_vlp16.txtpb" > "$work/seq_$i.txtpb"
    rig=()
    [ "$i" = 1 ] && rig=(--out_rig="$data/rig.txtpb")
    "$bin/tiltcal_simulate" --params="$work/seq_$i.txtpb" --out_bag="$data/seq_$i.bag" \
      --out_truth="$data/seq_$i.truth.txtpb" "${rig[@]}" 2> /dev/null || return 1
  done
}

# flat_pair_fixture BUILD_DIR: the folder of the CTest fixture
# pipeline_flat_pair (flat_pair_fixture.sh), which holds
#   dataset/      the two sequences and the rig as simulated
#   local/flat/   a copy of dataset/ with Makefile.pipeline's run of goals all
#                 and gravity-reference (-j2) in out/, made from local/ with
#                 DATASET=flat: a relative dataset path, so that a run of
#                 another copy named flat, from another folder, records the
#                 same paths in its outputs.
flat_pair_fixture() {
  echo "$1/test_data/pipeline_flat_pair"
}
