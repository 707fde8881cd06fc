#!/usr/bin/env bash
# tiltcal_simulate benchmark (docs/design.md §13): time to generate the 60 s VLP-16
# tilted Husky sequence (stages/simulate/scenarios/tilted_husky_vlp16.txtpb,
# ~12 M points, 600 scans, 12,000 IMU samples) per chunk compression and
# thread count, with two anchors measured in the same run:
#   - real time: the sequence's 60 s (real-time factor = 60 s / wall);
#   - I/O floor: copying the produced bag (cp, warm cache) — the cost of just
#     moving that many bytes (ratio = wall / copy wall).
# cpu_s (user + sys) is shown too: on a shared, loaded machine it is the
# steadier figure (wall ≈ cpu_s / threads on idle cores).
#
# Usage: bench/simulate/run_simulate_bench.sh [options]; tiltcal_simulate is
# built into --build_dir (Release) when it has none.
set -euo pipefail

BENCH_BUILD_DIR=build-bench
. "$(dirname "$0")/../common.sh"
bench_flag --threads THREADS "1 2" "values of num_threads to run"
bench_flag --compressions COMPRESSIONS "NONE LZ4" "chunk compressions to run (NONE LZ4 BZ2)"
bench_flag --duration DURATION 60 "sequence length, s"
bench_parse "$@"

if [ ! -x "$BUILD_DIR/bin/tiltcal_simulate" ]; then
  cmake -S "$REPO" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$BUILD_DIR" --target tiltcal_simulate -j2
fi
require_binaries tiltcal_simulate
SIM="$BIN/tiltcal_simulate"
WORK="$SCRATCH/tiltcal_simulate_bench"
mkdir -p "$WORK"
SCENARIO="$REPO/stages/simulate/scenarios/tilted_husky_vlp16.txtpb"

now() { date +%s.%N; }

printf '%-6s %-7s %9s %8s %10s %9s %10s %11s %9s\n' compr threads wall_s cpu_s "x_realtime" bag_MB Mpoints_s copy_wall_s "x_copy"
for compression in $COMPRESSIONS; do
  for threads in $THREADS; do
    params="$WORK/scenario_${compression}_${threads}.txtpb"
    sed -e "s/^duration_s: .*/duration_s: $DURATION/" \
        -e "s/^num_threads: .*/num_threads: $threads/" \
        -e "s/^  compression: .*/  compression: $compression/" "$SCENARIO" > "$params"
    bag="$WORK/sim_${compression}.bag"
    t0=$(now)
    /usr/bin/time -f "%U %S" -o "$WORK/time.txt" \
      "$SIM" --params="$params" --out_bag="$bag" --out_truth="$WORK/truth.txtpb" 2> "$WORK/log.txt"
    t1=$(now)
    cpu=$(awk '{print $1 + $2}' "$WORK/time.txt")
    points=$(sed -n 's/.* scans, \([0-9]*\) points.*/\1/p' "$WORK/log.txt")
    cat "$bag" > /dev/null
    c0=$(now)
    cp "$bag" "$WORK/copy.bag"
    sync "$WORK/copy.bag" 2>/dev/null || true
    c1=$(now)
    rm -f "$WORK/copy.bag"
    awk -v c="$compression" -v th="$threads" -v t0="$t0" -v t1="$t1" -v c0="$c0" -v c1="$c1" \
        -v d="$DURATION" -v bytes="$(stat -c %s "$bag")" -v pts="$points" -v cpu="$cpu" 'BEGIN {
      w = t1 - t0; cw = c1 - c0;
      printf "%-6s %-7s %9.2f %8.2f %10.1f %9.1f %10.2f %11.2f %9.1f\n",
             c, th, w, cpu, d / w, bytes / 1e6, pts / w / 1e6, cw, w / cw }'
  done
done
rm -rf "$WORK"
