#!/usr/bin/env bash
# Setup of the CTest fixture pipeline_flat_pair, which end_to_end_test.sh and
# slurm_test.sh read: the two flat 12 s sequences (flat_pair_dataset.sh)
# simulated once and run once through every stage with Makefile.pipeline
# (-j2), in the folder flat_pair_fixture names.
#   flat_pair_fixture.sh BUILD_DIR
set -euo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=$(cd "${1:?usage: flat_pair_fixture.sh BUILD_DIR}" && pwd)
source "$(dirname "$0")/flat_pair_dataset.sh"
FIXTURE=$(flat_pair_fixture "$BUILD")
rm -rf "$FIXTURE"
mkdir -p "$FIXTURE/local"
simulate_flat_pair "$BUILD/bin" "$SRC" "$FIXTURE" "$FIXTURE/dataset" ||
  { echo "FAIL: tiltcal_simulate failed" >&2; exit 1; }
cp -a "$FIXTURE/dataset" "$FIXTURE/local/flat"
(cd "$FIXTURE/local" && make --no-print-directory -f "$SRC/Makefile.pipeline" DATASET=flat \
  BIN="$BUILD/bin" -j2 all gravity-reference) > "$FIXTURE/local/make.log" 2>&1 ||
  { tail -20 "$FIXTURE/local/make.log"; echo "FAIL: the pipeline failed" >&2; exit 1; }
echo PASS
