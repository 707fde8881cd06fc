#!/usr/bin/env bash
# Livox decode benchmark (see README.md beside this file, "Livox CustomMsg").
#
# Simulates the 16 s flat sequence of tests/stages/calibrate twice, once with
# a VLP-16 (PointCloud2, the anchor) and once with a Livox Mid-360
# (livox_ros_driver/CustomMsg, tests/stages/calibrate/short_flat_mid360.txtpb),
# decodes each REPEATS times with the built tiltcal_decode and prints, per
# bag, the median wall, MB/s (bag bytes / wall), points read per second
# (every point of every message, dropped ones included) and the ratio of
# the Livox points/s to the VLP-16's in the same run, with the load average.
#
# Usage: bench/decode/run_livox_decode_bench.sh [--build_dir DIR] [--repeats N] [--scratch DIR]
set -euo pipefail

. "$(dirname "$0")/../common.sh"
bench_flag --repeats REPEATS 5 "decodes per bag, median shown"
bench_parse "$@"
require_binaries tiltcal_simulate tiltcal_decode
WORK=$(mktemp -d "$SCRATCH/tiltcal_livox_bench.XXXXXX")
bench_on_exit 'rm -rf "$WORK"'

# The two bags.
"$BIN/tiltcal_simulate" --quiet --params="$REPO/tests/stages/calibrate/short_flat_vlp16.txtpb" \
  --out_bag="$WORK/vlp16.bag" --out_truth="$WORK/vlp16.truth.txtpb" --out_rig="$WORK/rig.txtpb"
"$BIN/tiltcal_simulate" --quiet --params="$REPO/tests/stages/calibrate/short_flat_mid360.txtpb" \
  --out_bag="$WORK/mid360.bag" --out_truth="$WORK/mid360.truth.txtpb" --out_rig="$WORK/rig360.txtpb"

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores"
printf '%-8s %10s %10s %10s %14s %8s\n' bag MB wall_s MB/s points/s ratio
anchor_pps=""
for name in vlp16 mid360; do
  bag="$WORK/$name.bag"
  cat "$bag" > /dev/null  # warm page cache
  walls=()
  for _ in $(seq "$REPEATS"); do
    start=$(date +%s.%N)
    "$BIN/tiltcal_decode" --bag="$bag" --out_imu="$WORK/imu.binpb" \
      --out_scans="$WORK/scans.binpb.lz4" 2> "$WORK/$name.log"
    walls+=("$(echo "$(date +%s.%N) - $start" | bc)")
  done
  median=$(printf '%s\n' "${walls[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
  # Points read: written + every dropped point, the counts of the summary
  # line (the mask "(Livox tag & 0x0f)" is cut off first).
  points=$(grep -E '^  points:' "$WORK/$name.log" | sed 's/ (Livox.*//' | grep -oE '[0-9]+' |
    awk '{s+=$1} END {print s}')
  bytes=$(stat -c %s "$bag")
  pps=$(echo "$points / $median" | bc -l)
  [ -z "$anchor_pps" ] && anchor_pps=$pps
  printf '%-8s %10.1f %10.3f %10.1f %14.0f %8.2f\n' "$name" "$(echo "$bytes / 1000000" | bc -l)" \
    "$median" "$(echo "$bytes / 1000000 / $median" | bc -l)" "$pps" "$(echo "$pps / $anchor_pps" | bc -l)"
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
