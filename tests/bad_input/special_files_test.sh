#!/usr/bin/env bash
# Every input slot given a FIFO (nobody writes it), a device, or a folder of
# bags holding one: each must be refused in under a second with exit 1 and
# exactly one line naming it (never a hang, never an endless read). Then an
# MCAP whose chunk decompresses to 2 GiB: refused by the decompressed-chunk
# limit, and, with the limit raised, an out-of-memory error of one line
# under a 1.5 GB address-space limit (never an abort).
#   special_files_test.sh BUILD_DIR
set -uo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${1:?usage: special_files_test.sh BUILD_DIR}" && pwd)/bin
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
GOOD=$WORK/good
OUT=$WORK/out
mkdir -p "$GOOD" "$OUT"
die() { echo "FAIL: $*" >&2; exit 1; }

# ---- valid inputs: a 3 s simulated sequence through decode and ground ----
source "$(dirname "$0")/valid_inputs.sh"
make_valid_inputs "$BIN" "$SRC" "$GOOD" "$WORK/log" || die "the valid inputs"

# ---- special files ----
FIFO=$WORK/fifo.bag
mkfifo "$FIFO"
# rosbag2 folders whose metadata.yaml is a FIFO, or a link to /dev/zero.
mkdir "$WORK/fifo_meta" "$WORK/zero_meta"
mkfifo "$WORK/fifo_meta/metadata.yaml"
ln -s /dev/zero "$WORK/zero_meta/metadata.yaml"
# Folders of bags: the good bag and a FIFO, a dangling link, a link loop.
for f in fifo dangling loop; do
  mkdir "$WORK/folder_$f" && cp "$GOOD/seq.bag" "$WORK/folder_$f/a.bag"
done
mkfifo "$WORK/folder_fifo/b.bag"
ln -s "$WORK/nowhere.bag" "$WORK/folder_dangling/b.bag"
ln -s "$WORK/folder_loop/b.bag" "$WORK/folder_loop/b.bag"

failures=0
cases=0
# expect_refusal FILE COMMAND...: exit 1 within a second, one line naming
# FILE, nothing in $OUT.
expect_refusal() {
  local file=$1
  shift
  cases=$((cases + 1))
  rm -rf "$OUT" && mkdir -p "$OUT"
  local start output rc elapsed_ms lines problem=""
  start=$(date +%s%N)
  # A hang ends after 10 s (shell functions put `timeout` in front themselves).
  if [ -x "$1" ]; then output=$(timeout 10 "$@" 2>&1 < /dev/null)
  else output=$("$@" 2>&1 < /dev/null); fi
  rc=$?
  elapsed_ms=$((($(date +%s%N) - start) / 1000000))
  lines=$(printf '%s\n' "$output" | grep -c .)
  if [ "$rc" != 1 ]; then problem="exit $rc (expected 1)"
  elif [ "$elapsed_ms" -ge 1000 ]; then problem="took $elapsed_ms ms"
  elif [ "$lines" != 1 ]; then problem="$lines output lines (expected 1)"
  elif ! printf '%s' "$output" | grep -qF -- "$file"; then problem="the line does not name $file"
  elif [ -n "$(ls -A "$OUT")" ]; then problem="left in the output directory: $(ls -A "$OUT")"
  fi
  if [ -n "$problem" ]; then
    failures=$((failures + 1))
    echo "FAIL: ${*##*/}"
    echo "      $problem; output: $output"
  fi
}

decode() {  # decode BAG [RIG [PARAMS]]
  timeout 10 "$BIN/tiltcal_decode" --bag="$1" --rig="${2:-$GOOD/rig.txtpb}" ${3:+--params="$3"} \
    --out_imu="$OUT/imu.binpb" --out_scans="$OUT/scans.binpb.lz4"
}
expect_refusal "$FIFO" decode "$FIFO"
expect_refusal /dev/zero decode /dev/zero
expect_refusal "$WORK/fifo_meta/metadata.yaml" decode "$WORK/fifo_meta"
expect_refusal "$WORK/zero_meta/metadata.yaml" decode "$WORK/zero_meta"
expect_refusal "$WORK/folder_fifo/b.bag" decode "$WORK/folder_fifo"
expect_refusal "$WORK/folder_dangling/b.bag" decode "$WORK/folder_dangling"
expect_refusal "$WORK/folder_loop/b.bag" decode "$WORK/folder_loop"
expect_refusal "$FIFO" decode "$GOOD/seq.bag" "$FIFO"
expect_refusal "$FIFO" decode "$GOOD/seq.bag" "$GOOD/rig.txtpb" "$FIFO"

expect_refusal "$FIFO" "$BIN/tiltcal_ground" --imu="$FIFO" --scans="$GOOD/scans.binpb.lz4" \
  --rig="$GOOD/rig.txtpb" --out_ground="$OUT/ground.binpb"
expect_refusal "$FIFO" "$BIN/tiltcal_ground" --imu="$GOOD/imu.binpb" --scans="$FIFO" \
  --rig="$GOOD/rig.txtpb" --out_ground="$OUT/ground.binpb"
expect_refusal "$FIFO" "$BIN/tiltcal_gravity" --imu="$GOOD/imu.binpb" --ground="$FIFO" \
  --rig="$GOOD/rig.txtpb" --out="$OUT/gravity.txtpb"
for slot in imu scans ground; do
  declare -A in=([imu]="$GOOD/imu.binpb" [scans]="$GOOD/scans.binpb.lz4"
                 [ground]="$GOOD/ground.binpb")
  in[$slot]=$FIFO
  expect_refusal "$FIFO" "$BIN/tiltcal_calibrate" --imu="${in[imu]}" --scans="${in[scans]}" \
    --ground="${in[ground]}" --gravity="$GOOD/gravity.txtpb" --rig="$GOOD/rig.txtpb" \
    --out="$OUT/calibration.txtpb"
done

expect_refusal "$FIFO" "$BIN/tiltcal_inspect" check --bag="$FIFO"
expect_refusal "$WORK/fifo_meta/metadata.yaml" "$BIN/tiltcal_inspect" check \
  --bag="$WORK/fifo_meta"
expect_refusal "$FIFO" "$BIN/tiltcal_inspect" pcd "$FIFO" --out="$OUT/scan.pcd"
expect_refusal "$FIFO" "$BIN/tiltcal_inspect" pcd "$GOOD/scans.binpb.lz4" --ground="$FIFO" \
  --out="$OUT/scan.pcd"
expect_refusal "$FIFO" "$BIN/tiltcal_inspect" cat "$FIFO"

# ---- an MCAP chunk that decompresses to 2 GiB (zstd RLE blocks) ----
/usr/bin/python3 - "$WORK/huge_chunk.mcap" <<'EOF'
import struct, sys
blocks = 16384  # x 128 KiB of zeros = 2 GiB, 4 bytes per block
frame = b"\x28\xb5\x2f\xfd\x00\x38" + b"".join(
    struct.pack("<I", (1 if b + 1 == blocks else 0) | (1 << 1) | (131072 << 3))[:3] + b"\0"
    for b in range(blocks))
def record(op, content): return bytes([op]) + struct.pack("<Q", len(content)) + content
def s(x): return struct.pack("<I", len(x)) + x
chunk = struct.pack("<QQQI", 0, 0, blocks * 131072, 0) + s(b"zstd") + struct.pack("<Q", len(frame)) + frame
magic = b"\x89MCAP0\r\n"
data = (magic + record(1, s(b"ros2") + s(b"")) + record(6, chunk) + record(15, struct.pack("<I", 0))
        + record(2, struct.pack("<QQI", 0, 0, 0)) + magic)
open(sys.argv[1], "wb").write(data)
EOF
expect_refusal "$WORK/huge_chunk.mcap" decode "$WORK/huge_chunk.mcap"
sed -E 's/^max_decompressed_chunk_mib:.*/max_decompressed_chunk_mib: 4096/' \
  "$SRC/stages/decode/default_params.txtpb" > "$WORK/big_chunks.txtpb"
grep -q "^max_decompressed_chunk_mib: 4096$" "$WORK/big_chunks.txtpb" ||
  die "no max_decompressed_chunk_mib in the decode defaults"
cases=$((cases + 1))
output=$( (ulimit -v 1500000; "$BIN/tiltcal_decode" --bag="$WORK/huge_chunk.mcap" \
  --params="$WORK/big_chunks.txtpb" --out_imu="$OUT/imu.binpb" \
  --out_scans="$OUT/scans.binpb.lz4") 2>&1)
rc=$?
if [ "$rc" != 1 ] || [ "$(printf '%s\n' "$output" | grep -c .)" != 1 ] ||
   ! printf '%s' "$output" | grep -q "^tiltcal_decode: out of memory"; then
  failures=$((failures + 1))
  echo "FAIL: decode of a 2 GiB chunk under ulimit -v: exit $rc; output: $output"
fi

echo "$cases special-file cases, $failures failures"
[ "$failures" = 0 ]
