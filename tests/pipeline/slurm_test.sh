#!/usr/bin/env bash
# Makefile.pipeline through a real Slurm controller: a one-node cluster on
# this machine (scripts/slurm_local_cluster.sh), two short simulated
# sequences run with LAUNCH="srun -N1 -n1 …" -j2; the CTest fixture
# pipeline_flat_pair (flat_pair_fixture.sh) holds the same sequences and
# their local run (no LAUNCH). Every $(LAUNCH) recipe must have run as one
# Slurm job that completed (the controller's job completion log), and every
# output must equal the local run's but for what the clock decides
# (created_utc, the calibration's timings).
#   slurm_test.sh BUILD_DIR
# Exit 77 (skipped) without root or without Slurm and munge
# (scripts/setup.sh --cluster installs them).
set -euo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=$(cd "${1:?usage: slurm_test.sh BUILD_DIR}" && pwd)
BIN=$BUILD/bin
fail() { echo "FAIL: $*" >&2; exit 1; }
export PATH=$PATH:/usr/sbin:/sbin  # the daemons

for tool in srun sinfo slurmctld slurmd munged mungekey; do
  command -v "$tool" > /dev/null ||
    { echo "SKIP: no $tool (install Slurm and munge: scripts/setup.sh --cluster)"; exit 77; }
done
[ "$(id -u)" -eq 0 ] || { echo "SKIP: the local Slurm cluster needs root (slurmd)"; exit 77; }

WORK=$(mktemp -d)
CLUSTER=$WORK/cluster
cleanup() {
  bash "$SRC/scripts/slurm_local_cluster.sh" stop "$CLUSTER" 2> /dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT
trap 'exit 143' TERM INT HUP

# The two flat 12 s sequences of end_to_end_test.sh and their local run:
# the fixture's dataset and local/flat (flat_pair_dataset.sh).
source "$(dirname "$0")/flat_pair_dataset.sh"
FIXTURE=$(flat_pair_fixture "$BUILD")
[ -d "$FIXTURE/local/flat/out" ] ||
  fail "no $FIXTURE/local/flat/out: ctest runs tests/pipeline/flat_pair_fixture.sh first"

bash "$SRC/scripts/slurm_local_cluster.sh" start "$CLUSTER"
export SLURM_CONF=$CLUSTER/slurm.conf

# A copy of the fixture's dataset named flat, run from $WORK/slurm_run with
# DATASET=flat as the local run was from local/: the paths the outputs
# record are the same.
GOALS=(all gravity-reference)  # every recipe of Makefile.pipeline that has $(LAUNCH)
mkdir -p "$WORK/slurm_run"
cp -a "$FIXTURE/dataset" "$WORK/slurm_run/flat"
(cd "$WORK/slurm_run" && make --no-print-directory -f "$SRC/Makefile.pipeline" DATASET=flat \
  BIN="$BIN" -j2 LAUNCH="srun -N1 -n1 --time=10 --quiet" "${GOALS[@]}") > "$WORK/slurm.log" 2>&1 ||
  { tail -20 "$WORK/slurm.log"; fail "the pipeline failed under Slurm"; }
bash "$SRC/scripts/slurm_local_cluster.sh" stop "$CLUSTER"

# One completed job per $(LAUNCH) recipe: five stages per sequence, then the
# dataset's calibration and its gravity reference (the daemons are stopped:
# the job completion log is complete).
expected=$(for s in seq_1 seq_2; do
  printf '%s\n' tiltcal_decode tiltcal_initial_extrinsic tiltcal_ground tiltcal_gravity tiltcal_calibrate
done; printf '%s\n' tiltcal_dataset_calibration tiltcal_gravity_reference)
jobs_file=$CLUSTER/jobcomp.txt
[ -s "$jobs_file" ] || fail "no job completion records in $jobs_file"
ran=$(sed -n 's/.* Name=\([^ ]*\) .*/\1/p' "$jobs_file" | sort)
[ "$ran" = "$(sort <<< "$expected")" ] ||
  fail "the Slurm jobs ($(echo $ran)) are not the stages with \$(LAUNCH) ($(sort <<< "$expected" | xargs))"
not_completed=$(grep -v ' JobState=COMPLETED .* ExitCode=0:0' "$jobs_file" || true)
[ -z "$not_completed" ] || fail "jobs that did not complete: $not_completed"
echo "Slurm jobs: $(wc -l < "$jobs_file") completed ($(echo $ran))"

# The same files, each byte-equal or equal but for what the clock decides
# (what differs between two runs of one binary on one input).
SLURM_OUT=$WORK/slurm_run/flat/out
LOCAL_OUT=$FIXTURE/local/flat/out
(cd "$SLURM_OUT" && find . -type f -printf '%P\n' | sort) > "$WORK/slurm_files"
(cd "$LOCAL_OUT" && find . -type f -printf '%P\n' | sort) > "$WORK/local_files"
diff "$WORK/slurm_files" "$WORK/local_files" > /dev/null ||
  fail "Slurm and local runs wrote different files: $(diff "$WORK/slurm_files" "$WORK/local_files" | grep '^[<>]' | xargs)"
grep -qx 'seq_1/calibration\.txtpb' "$WORK/slurm_files" || fail "no out/seq_1/calibration.txtpb"

# A text output without the provenance's created_utc, the calibration's
# solver.seconds_per_iteration and timings { seconds }, and the size_bytes of
# an input that is another output (a calibration.txtpb, whose timings change
# its size; it is compared itself).
without_run_times() {
  awk -v out="flat/out/" '
    /^[[:space:]]*(created_utc|seconds_per_iteration): / { next }
    /^timings \{/ { in_timings = 1 }
    /^\}/ { in_timings = 0 }
    in_timings && /^[[:space:]]*seconds: / { next }
    /^[[:space:]]*path: "/ { input_from_out = index($0, "\"" out) > 0 }
    input_from_out && /^[[:space:]]*size_bytes: / { input_from_out = 0; next }
    { print }'
}
# A record stream (lz4 frames decompressed): equal but for the bytes of the
# header's created_utc (fixed length: nothing after it moves).
stream_bytes() { if [[ "$1" == *.lz4 ]]; then lz4 -dc -- "$1"; else cat -- "$1"; fi; }
streams_equal_but_created_utc() {
  local utc offset
  utc=$("$BIN/tiltcal_inspect" info "$1" | sed -n 's/^created_utc: "\(.*\)"$/\1/p')
  [ -n "$utc" ] || return 1
  offset=$(grep -baoF -m1 -- "$utc" <(stream_bytes "$1") | cut -d: -f1 || true)
  [ -n "$offset" ] || return 1
  cmp -l <(stream_bytes "$1") <(stream_bytes "$2") > "$WORK/cmp" 2>&1 || true
  # cmp -l: one line per differing byte, its 1-based offset first.
  awk -v first=$((offset + 1)) -v last=$((offset + ${#utc})) \
    '$1 !~ /^[0-9]+$/ || $1 < first || $1 > last { bad = 1 } END { exit bad }' "$WORK/cmp"
}
byte_equal=0
while read -r f; do
  a=$SLURM_OUT/$f
  b=$LOCAL_OUT/$f
  if cmp -s "$a" "$b"; then
    byte_equal=$((byte_equal + 1))
  elif [[ "$f" == *.txtpb ]]; then
    diff <(without_run_times < "$a") <(without_run_times < "$b") ||
      fail "out/$f differs between the Slurm and the local run (beyond the run times)"
  elif [[ "$f" == *.binpb || "$f" == *.binpb.lz4 ]]; then
    streams_equal_but_created_utc "$a" "$b" ||
      fail "out/$f differs between the Slurm and the local run (beyond created_utc): $(head -3 "$WORK/cmp" | xargs)"
  else
    fail "out/$f differs between the Slurm and the local run"
  fi
done < "$WORK/slurm_files"
echo "outputs: $(wc -l < "$WORK/slurm_files") files equal to the local run's ($byte_equal byte for byte, the others but for the run times)"
echo PASS
