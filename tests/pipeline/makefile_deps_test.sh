#!/usr/bin/env bash
# Tests the dependency graph of Makefile.pipeline with stub stage binaries:
# which commands run after a params file, a binary or an input changes, that a
# failed stage leaves no output, and that -j runs sequences in parallel.
set -euo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
BIN=$WORK/bin
DATA=$WORK/data
mkdir -p "$BIN" "$DATA/params"

# Stub stages and plot interpreter (stub_stages.sh).
source "$(dirname "$0")/stub_stages.sh"
make_stub_stages "$BIN"

echo 'imu_height_m: 0.3' > "$DATA/rig.txtpb"
for stage in decode ground gravity calibrate; do echo "# $stage" > "$DATA/params/$stage.txtpb"; done
touch "$DATA/seq_a.bag" "$DATA/seq_b.bag"
MAKE=(make --no-print-directory -f "$SRC/Makefile.pipeline" DATASET="$DATA" BIN="$BIN" PYTHON="$BIN/python")

fail() { echo "FAIL: $*" >&2; exit 1; }
# Stages that `make -n` would run, one "stage sequence" per line, sorted.
planned() {
  "${MAKE[@]}" -n "$@" | sed -e ':a' -e '/\\$/N; s/\\\n//; ta' | perl -ne '
    next if /^echo /; next unless /(tiltcal_[a-z_]+|plot_[a-z_]+\.py)/; my $stage = $1;
    my ($seq) = $stage =~ /^tiltcal_(dataset_calibration|gravity_reference)$/ ? ("") :
      m{/out/([^/ ]+)/} ? ($1) : m{/([^/ ]+)\.bag} ? ($1) : ("");
    print $seq eq "" ? "$stage\n" : "$stage $seq\n";' | sort -u | tr '\n' ';'
}
expect() {  # expect "<description>" "<planned>" "<expected>"
  [ "$2" = "$3" ] || fail "$1: planned '$2', expected '$3'"
  echo "ok: $1"
}
# make compares mtimes: returns once a file written now is newer than every
# file written so far (file times advance by the file system's clock tick).
sleep_past() {
  touch "$WORK/last"
  until [ "$WORK/now" -nt "$WORK/last" ]; do sleep 0.01; touch "$WORK/now"; done
}

expect "fresh dataset runs every stage" "$(planned)" \
"plot_extrinsics.py;plot_ground_timeline.py seq_a;plot_ground_timeline.py seq_b;tiltcal_calibrate seq_a;tiltcal_calibrate seq_b;tiltcal_dataset_calibration;tiltcal_decode seq_a;tiltcal_decode seq_b;tiltcal_gravity seq_a;tiltcal_gravity seq_b;tiltcal_ground seq_a;tiltcal_ground seq_b;tiltcal_initial_extrinsic seq_a;tiltcal_initial_extrinsic seq_b;tiltcal_inspect seq_a;tiltcal_inspect seq_b;tiltcal_report;"

"${MAKE[@]}" -j2 all > /dev/null
for s in seq_a seq_b; do
  for f in imu.binpb scans.binpb.lz4 ground.binpb gravity.txtpb calibration.txtpb ground.csv ground_timeline.png; do
    [ -f "$DATA/out/$s/$f" ] || fail "-j2 all did not make out/$s/$f"
  done
done
[ -f "$DATA/out/repeatability.txt" ] && [ -f "$DATA/out/extrinsic_spread.png" ] || fail "no report"
[ -f "$DATA/out/calibration.txtpb" ] || fail "no dataset calibration"
expect "up to date after a full run" "$(planned)" ""

sleep_past; echo 'edited' >> "$DATA/params/ground.txtpb"
expect "editing the ground params reruns ground and downstream, nothing upstream" "$(planned)" \
"plot_extrinsics.py;plot_ground_timeline.py seq_a;plot_ground_timeline.py seq_b;tiltcal_calibrate seq_a;tiltcal_calibrate seq_b;tiltcal_dataset_calibration;tiltcal_gravity seq_a;tiltcal_gravity seq_b;tiltcal_ground seq_a;tiltcal_ground seq_b;tiltcal_inspect seq_a;tiltcal_inspect seq_b;tiltcal_report;"
"${MAKE[@]}" all > /dev/null

sleep_past; echo 'edited' >> "$DATA/params/calibrate.txtpb"
expect "calibrate params rerun the starting extrinsic and everything after it (the rotation search reads them)" "$(planned)" \
"plot_extrinsics.py;plot_ground_timeline.py seq_a;plot_ground_timeline.py seq_b;tiltcal_calibrate seq_a;tiltcal_calibrate seq_b;tiltcal_dataset_calibration;tiltcal_gravity seq_a;tiltcal_gravity seq_b;tiltcal_ground seq_a;tiltcal_ground seq_b;tiltcal_initial_extrinsic seq_a;tiltcal_initial_extrinsic seq_b;tiltcal_inspect seq_a;tiltcal_inspect seq_b;tiltcal_report;"
"${MAKE[@]}" all > /dev/null

sleep_past; touch "$DATA/params/ground.txtpb"
expect "editing the ground override again reruns ground" "$(planned ground)" \
"tiltcal_ground seq_a;tiltcal_ground seq_b;"
"${MAKE[@]}" all > /dev/null

sleep_past; touch "$DATA/seq_b.bag"
expect "a changed bag reruns that sequence only" "$(planned seq_b)" \
"tiltcal_calibrate seq_b;tiltcal_decode seq_b;tiltcal_gravity seq_b;tiltcal_ground seq_b;tiltcal_initial_extrinsic seq_b;"
"${MAKE[@]}" all > /dev/null

sleep_past; rm "$BIN/tiltcal_gravity"; cp "$BIN/stub" "$BIN/tiltcal_gravity"
expect "a rebuilt gravity binary reruns gravity and downstream" "$(planned calibrate)" \
"tiltcal_calibrate seq_a;tiltcal_calibrate seq_b;tiltcal_gravity seq_a;tiltcal_gravity seq_b;"
"${MAKE[@]}" all > /dev/null

# A tilted dataset takes its flat-ground gravity reference from the rig.
mkdir -p "$DATA/flat"; echo 'gravity_flat_in_imu { z: -9.81 }' > "$DATA/flat/gravity.txtpb"
sleep_past; printf 'imu_height_m: 0.3\ngravity_reference: "flat/gravity.txtpb"\n' > "$DATA/rig.txtpb"
"${MAKE[@]}" all > /dev/null
sleep_past; touch "$DATA/flat/gravity.txtpb"
expect "a changed gravity reference reruns gravity and downstream" "$(planned calibrate)" \
"tiltcal_calibrate seq_a;tiltcal_calibrate seq_b;tiltcal_gravity seq_a;tiltcal_gravity seq_b;"
"${MAKE[@]}" all > /dev/null

# ... or from a flat dataset folder: its out/gravity_reference.txtpb, from
# its calibrations, brought up to date by make on the tilted dataset.
FLAT=$WORK/flat_dataset
mkdir -p "$FLAT"; echo 'imu_height_m: 0.3' > "$FLAT/rig.txtpb"; touch "$FLAT/run_1.bag" "$FLAT/run_2.bag"
sleep_past; printf 'imu_height_m: 0.3\ngravity_reference: "../flat_dataset"\n' > "$DATA/rig.txtpb"
"${MAKE[@]}" all > /dev/null
for f in run_1/calibration.txtpb run_2/calibration.txtpb gravity_reference.txtpb; do
  [ -s "$FLAT/out/$f" ] || fail "make on the tilted dataset did not make the flat dataset's out/$f"
done
make --no-print-directory -n -B -f "$SRC/Makefile.pipeline" DATASET="$FLAT" BIN="$BIN" \
  gravity-reference | sed -e ':a' -e '/\\$/N; s/\\\n//; ta' |
  grep -q -- "tiltcal_gravity_reference' .*--out='$FLAT/out/gravity_reference.txtpb'" || fail "no gravity-reference target on the flat dataset"
mtime() { stat -c %Y.%y "$1"; }
before=$(mtime "$DATA/out/seq_a/gravity.txtpb")
sleep_past; "${MAKE[@]}" all > /dev/null
[ "$(mtime "$DATA/out/seq_a/gravity.txtpb")" = "$before" ] ||
  fail "an up-to-date flat dataset reference reran the tilted gravity stage"
echo "ok: a flat dataset folder as the gravity reference, up to date"
sleep_past; echo 'edited' >> "$FLAT/run_2.bag"
"${MAKE[@]}" all > /dev/null
[ "$FLAT/out/gravity_reference.txtpb" -nt "$FLAT/run_2.bag" ] ||
  fail "a changed flat bag did not rebuild the flat dataset's reference"
[ "$(mtime "$DATA/out/seq_a/gravity.txtpb")" != "$before" ] ||
  fail "a rebuilt flat dataset reference did not rerun the tilted gravity stage"
echo "ok: a changed flat dataset rebuilds its reference and the tilted gravity stage"
printf 'imu_height_m: 0.3\ngravity_reference: "flat/gravity.txtpb"\n' > "$DATA/rig.txtpb"
"${MAKE[@]}" all > /dev/null

sleep_past; touch "$DATA/params/ground.txtpb"
if TILTCAL_STUB_FAIL=tiltcal_ground "${MAKE[@]}" ground > /dev/null 2>&1; then
  fail "a failing stage did not fail make"
fi
[ ! -e "$DATA/out/seq_a/ground.binpb" ] || fail "a failed stage left its output behind"
echo "ok: a failed stage leaves no output"

help_text=$("${MAKE[@]}" help); grep -q LAUNCH <<<"$help_text" || fail "help does not document LAUNCH"
launched=$("${MAKE[@]}" LAUNCH="echo LAUNCHED" -n ground); grep -q "echo LAUNCHED .*tiltcal_ground" <<<"$launched" ||
  fail "LAUNCH does not prefix stage commands"
echo "ok: help and LAUNCH"
"${MAKE[@]}" all > /dev/null
sleep_past; touch "$DATA/params/calibrate.txtpb"
if TILTCAL_STUB_SUSPECT=tiltcal_calibrate "${MAKE[@]}" -k calibrate > /dev/null 2> "$WORK/suspect.log"; then
  fail "a SUSPECT calibration did not fail make"
fi
[ ! -e "$DATA/out/seq_a/calibration.txtpb" ] || fail "a SUSPECT calibration was kept as done"
[ -s "$DATA/out/seq_a/calibration.suspect.txtpb" ] || fail "a SUSPECT calibration was not kept aside"
grep -q "SUSPECT calibration: read the verdict_reasons in .*/out/seq_a/calibration.suspect.txtpb" \
  "$WORK/suspect.log" || fail "no message pointing to the suspect file: $(cat "$WORK/suspect.log")"
expect "a SUSPECT calibration is re-evaluated by the next make" "$(planned calibrate)" \
"tiltcal_calibrate seq_a;tiltcal_calibrate seq_b;"
"${MAKE[@]}" calibrate > /dev/null
[ -s "$DATA/out/seq_a/calibration.txtpb" ] && [ ! -e "$DATA/out/seq_a/calibration.suspect.txtpb" ] ||
  fail "a good rerun did not replace the suspect file"
echo "ok: a SUSPECT calibration fails its sequence, is kept aside and rerun"

"${MAKE[@]}" clean > /dev/null
[ -z "$(ls -A "$DATA/out")" ] || fail "clean left something in out/"

# ROS 2 sequences: an MCAP file and a rosbag2 folder are sequences beside the
# ROS 1 bags; decode gets the file or the folder, and a changed .db3 of a
# folder reruns that sequence only.
touch "$DATA/seq_c.mcap"
mkdir -p "$DATA/seq_d"
touch "$DATA/seq_d/metadata.yaml" "$DATA/seq_d/seq_d_0.db3" "$DATA/seq_d/seq_d_1.db3"
expect "MCAP files and ROS 2 bag folders are sequences" "$(planned decode)" \
"tiltcal_decode seq_a;tiltcal_decode seq_b;tiltcal_decode seq_c;tiltcal_decode seq_d;"
grep -q -- "--bag='$DATA/seq_c.mcap' " <<< "$("${MAKE[@]}" -n decode)" || fail "decode not given seq_c.mcap"
grep -q -- "--bag='$DATA/seq_d' " <<< "$("${MAKE[@]}" -n decode)" || fail "decode not given the folder seq_d"
"${MAKE[@]}" decode > /dev/null
sleep_past; touch "$DATA/seq_d/seq_d_1.db3"
expect "a changed .db3 reruns its folder's sequence only" "$(planned decode)" "tiltcal_decode seq_d;"
"${MAKE[@]}" decode > /dev/null

# Sequences of several bag files: a sub-folder of bags (split by time, or
# imu + lidar in any format) is one sequence named after it; a single .db3 is
# one too. Not sequences: a folder without bags (flat/), a dataset folder
# (rig.txtpb) with its bags, params/, and out/ (even with a bag in it).
mkdir -p "$DATA/seq_e" "$DATA/seq_f" "$DATA/other_dataset" "$DATA/out/stray"
touch "$DATA/seq_e/seq_e_0.bag" "$DATA/seq_e/seq_e_1.bag" "$DATA/seq_e/notes.txt"
touch "$DATA/seq_f/imu.bag" "$DATA/seq_f/lidar.mcap" "$DATA/seq_g.db3"
touch "$DATA/other_dataset/rig.txtpb" "$DATA/other_dataset/run.bag" "$DATA/params/x.bag" "$DATA/out/x.bag"
expect "folders of bag files and .db3 files are sequences" "$(planned decode)" \
"tiltcal_decode seq_e;tiltcal_decode seq_f;tiltcal_decode seq_g;"
grep -q -- "--bag='$DATA/seq_e' " <<< "$("${MAKE[@]}" -n decode)" || fail "decode not given the folder seq_e"
grep -q -- "--bag='$DATA/seq_g.db3' " <<< "$("${MAKE[@]}" -n decode)" || fail "decode not given seq_g.db3"
"${MAKE[@]}" decode > /dev/null
sleep_past; touch "$DATA/seq_f/lidar.mcap"
expect "a changed file of a folder of bags reruns that sequence only" "$(planned decode)" "tiltcal_decode seq_f;"
"${MAKE[@]}" decode > /dev/null
sleep_past; touch "$DATA/seq_e/seq_e_2.bag"
expect "a file added to a folder of bags reruns that sequence only" "$(planned decode)" "tiltcal_decode seq_e;"
touch "$DATA/seq_e.bag"
if "${MAKE[@]}" -n decode > /dev/null 2> "$WORK/same_name.log"; then
  fail "seq_e.bag beside the folder seq_e/ was accepted"
fi
grep -q "several inputs for the sequence(s) seq_e" "$WORK/same_name.log" ||
  fail "no error naming seq_e: $(cat "$WORK/same_name.log")"
echo "ok: a bag file and a folder of one name are an error"
echo "PASS"
