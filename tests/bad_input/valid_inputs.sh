# Sourced by the bad-input tests (bash): make_valid_inputs BIN SRC GOOD LOG
# writes a 3 s simulated sequence into GOOD (seq.bag, truth.txtpb, rig.txtpb)
# and runs it through decode, ground and gravity (imu.binpb,
# scans.binpb.lz4, ground.binpb, gravity.txtpb): the valid inputs of the
# slots a test does not make bad. Returns non-zero, LOG printed, when a
# stage fails.
make_valid_inputs() {
  local bin=$1 src=$2 good=$3 log=$4
  sed -E -e "s/^duration_s: .*/duration_s: 3/" \
    "$src/stages/simulate/scenarios/flat_vlp16.txtpb" > "$good/scenario.txtpb"
  "$bin/tiltcal_simulate" --params="$good/scenario.txtpb" --out_bag="$good/seq.bag" \
    --out_truth="$good/truth.txtpb" --out_rig="$good/rig.txtpb" 2> "$log" &&
    "$bin/tiltcal_decode" --bag="$good/seq.bag" --rig="$good/rig.txtpb" \
      --out_imu="$good/imu.binpb" --out_scans="$good/scans.binpb.lz4" 2> "$log" &&
    "$bin/tiltcal_ground" --imu="$good/imu.binpb" --scans="$good/scans.binpb.lz4" \
      --rig="$good/rig.txtpb" --out_ground="$good/ground.binpb" 2> "$log" &&
    "$bin/tiltcal_gravity" --imu="$good/imu.binpb" --ground="$good/ground.binpb" \
      --rig="$good/rig.txtpb" --out="$good/gravity.txtpb" 2> "$log" ||
    { cat "$log"; return 1; }
}
