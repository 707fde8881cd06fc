#!/usr/bin/env bash
# Names are data, never code: bag files, sequence folders, the dataset path
# and the rig's gravity_reference holding shell or make metacharacters are
# refused by Makefile.pipeline before anything runs (with and without -n),
# with one line naming the file and the characters; nothing they spell is
# executed. Safe names run. Stub stage binaries log every call.
#   makefile_names_test.sh [MAKEFILE]   (default: the repository's)
set -uo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
MAKEFILE=${1:-$SRC/Makefile.pipeline}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
BIN=$WORK/bin
mkdir -p "$BIN" "$WORK/deep/er/run"
source "$(dirname "$0")/stub_stages.sh"
make_stub_stages "$BIN"
export STUB_LOG=$WORK/stub.log
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# A dataset folder at $1 with a rig and a safe bag.
make_dataset() {
  mkdir -p "$1"
  echo 'imu_height_m: 0.3' > "$1/rig.txtpb"
  touch "$1/good.bag"
}
# run_make DATASET [make args...]: make from $WORK/deep/er/run (payloads that climb
# folders start there); stdout+stderr in $WORK/make.out, status in $status.
run_make() {
  local dataset=$1
  shift
  : > "$STUB_LOG"
  (cd "$WORK/deep/er/run" && timeout 60 make --no-print-directory -f "$MAKEFILE" DATASET="$dataset" BIN="$BIN" \
    PYTHON=true "$@") > "$WORK/make.out" 2>&1
  status=$?
}
# The payloads create a file named PWNED (or run a stage in the background).
pwned() { [ -n "$(find "$WORK" -name PWNED -print -quit)" ]; }
# expect_refused DESCRIPTION DATASET TEXT: make and make -n both fail
# without running anything, and the output names TEXT; nothing PWNED.
expect_refused() {
  local description=$1 dataset=$2 text=$3 mode
  for mode in run dry; do
    if [ $mode = dry ]; then run_make "$dataset" -n all; else run_make "$dataset" all; fi
    sleep 0.1  # a payload run in the background (&) has time to show
    if [ "$status" -eq 0 ]; then fail "$description ($mode): make exited 0"; fi
    if pwned; then fail "$description ($mode): the name ran a command"; fi
    if [ -s "$STUB_LOG" ]; then fail "$description ($mode): a stage ran: $(tr '\n' ' ' < "$STUB_LOG")"; fi
    if [ -e "$dataset/out" ]; then fail "$description ($mode): out/ was created"; fi
    if ! grep -qF -- "$text" "$WORK/make.out"; then
      fail "$description ($mode): the refusal does not name '$text': $(head -c 600 "$WORK/make.out")"
    fi
    if ! grep -q "cannot carry safely" "$WORK/make.out"; then
      fail "$description ($mode): not the names refusal: $(head -c 600 "$WORK/make.out")"
    fi
    find "$WORK" -name PWNED -delete
  done
  echo "ok: $description"
}

# Bag file names in the dataset.
bag_names=(
  'run1$(cd${IFS}..&&cd${IFS}..&&touch${IFS}PWNED).bag'
  'run`touch PWNED`.bag'
  'run$(touch PWNED).mcap'
  'a&touch PWNED&.bag'
  'a>PWNED.bag'
  'semi;touch PWNED;.db3'
  'hash#x.bag' 'colon:x.bag' 'percent%x.bag' 'paren(x).bag' 'back\slash.bag' 'pipe|x.bag'
  "quote'x.bag" 'dquote"x.bag' 'with space.bag' $'new\nline.bag' 'comma,x.bag' 'star*.bag'
)
for name in "${bag_names[@]}"; do
  dataset=$WORK/ds_bag
  rm -rf "$dataset"
  make_dataset "$dataset"
  touch "$dataset/$name"
  shown=$name
  [[ $name == *$'\n'* ]] && printf -v shown '%q' "$name"
  expect_refused "bag named $shown" "$dataset" "$dataset/$shown: the name holds characters"
done

# Sequence folders: a folder of bags and a ROS 2 bag folder.
for folder in 'seq$(touch PWNED)' 'seq`touch PWNED`' 'seq;touch PWNED' 'seq with space'; do
  for inner in x.bag metadata.yaml; do
    dataset=$WORK/ds_folder
    rm -rf "$dataset"
    make_dataset "$dataset"
    mkdir -p "$dataset/$folder"
    touch "$dataset/$folder/$inner"
    expect_refused "sequence folder '$folder' with $inner" "$dataset" "$dataset/$folder: the name holds"
  done
done

# The dataset path itself.
for name in 'dsname`{touch,PWNED}`' 'ds$(touch PWNED)' 'ds;touch PWNED' 'ds with space' "ds'q"; do
  dataset=$WORK/$name
  make_dataset "$dataset"
  expect_refused "dataset folder '$name'" "$dataset" "DATASET '$dataset' holds characters"
  rm -rf "$dataset"
done

# The rig's gravity_reference (a flat dataset folder or a file).
for reference in '../flat$(touch PWNED)' '../flat`touch PWNED`' 'flat;touch PWNED' 'g ref.txtpb'; do
  dataset=$WORK/ds_tilted
  rm -rf "$dataset"
  make_dataset "$dataset"
  printf 'imu_height_m: 0.3\ngravity_reference: "%s"\n' "$reference" > "$dataset/rig.txtpb"
  # The flat dataset it names, where that is a folder inside $WORK.
  [[ $reference == ../* ]] && make_dataset "$dataset/$reference"
  expect_refused "gravity_reference '$reference'" "$dataset" "rig.txtpb: gravity_reference '$reference' holds"
  rm -rf "$WORK"/flat*
done

# The verify target's REFERENCE (a path on the command line).
dataset=$WORK/ds_verify
make_dataset "$dataset"
for reference in 'ref$(touch PWNED).txtpb' 'ref`touch PWNED`' 'ref;touch PWNED' 'my ref.txtpb'; do
  for mode in run dry; do
    if [ $mode = dry ]; then
      run_make "$dataset" -n verify REFERENCE="$reference"
    else
      run_make "$dataset" verify REFERENCE="$reference"
    fi
    sleep 0.1
    [ "$status" -ne 0 ] || fail "REFERENCE '$reference' ($mode): make exited 0"
    pwned && fail "REFERENCE '$reference' ($mode): the name ran a command"
    [ -s "$STUB_LOG" ] && fail "REFERENCE '$reference' ($mode): a stage ran"
    grep -qF -- "REFERENCE '$reference' holds characters" "$WORK/make.out" ||
      fail "REFERENCE '$reference' ($mode): not refused: $(head -c 600 "$WORK/make.out")"
    find "$WORK" -name PWNED -delete
  done
  echo "ok: REFERENCE '$reference'"
done
rm -rf "$dataset"

# Safe names run, every character of the safe set in use.
dataset=$WORK/data-set_1+v2@site
make_dataset "$dataset"
touch "$dataset/Run-2024.05.01_a+b@c.bag"
mkdir -p "$dataset/seq.ros2-x_1" && touch "$dataset/seq.ros2-x_1/metadata.yaml"
run_make "$dataset" all
if [ "$status" -ne 0 ]; then fail "safe names: make exited $status: $(tail -c 600 "$WORK/make.out")"; fi
for s in good Run-2024.05.01_a+b@c seq.ros2-x_1; do
  [ -s "$dataset/out/$s/calibration.txtpb" ] || fail "safe names: no out/$s/calibration.txtpb"
done
[ -s "$dataset/out/report.html" ] || fail "safe names: no out/report.html"
pwned && fail "safe names: PWNED"
echo "ok: safe names run"

if [ "$failures" -gt 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo PASS
