#!/usr/bin/env bash
# Decode benchmark (docs/design.md §13; see README.md beside this file).
#
# Builds tiltcal_decode (Release) and, when Debian's C++ rosbag library
# installs, the anchor reader tiltcal_bench_rosbag_cpp_reader; generates
# lz4 bags of VLP-16-like clouds + 200 Hz IMU (reused when present); runs
# on the same large bag:
#   tiltcal_decode                      (ours, full decode to .binpb files)
#   C++ rosbag library reader           (anchor: rosbag::View + instantiate)
#   the same reader writing what it reads (second anchor: + stdio writes)
#   Python rosbag reader                (read_points, and numpy.frombuffer)
# each under /usr/bin/time -v, and prints wall s, MB/s (bag bytes / wall),
# points/s, peak RSS and the speed ratio against the C++ rosbag reader
# (anchor wall / tool wall; > 1 = faster than the anchor). tiltcal_decode is
# also run on a smaller bag to show that its peak memory does not grow with
# the bag size. Runs are on a warm page cache (each bag is read once first).
#
# Usage: bench/decode/run_decode_bench.sh [options]; tiltcal_decode is built
# into --build_dir (Release). The bags are reused from --scratch DIR when
# given (a fresh scratch is removed on exit, unless --keep).
# Exit status is non-zero when a step fails; the table is still printed for
# the steps that ran.
set -euo pipefail

BENCH_BUILD_DIR=build-bench
. "$(dirname "$0")/../common.sh"
bench_flag --size_gb SIZE_GB 1.0 "large bag size, 1e9 bytes"
bench_flag --small_gb SMALL_GB 0.25 "small bag size for the memory check"
bench_flag --repeats REPEATS 3 "runs of tiltcal_decode and the C++ reader; the table shows the median wall and the largest RSS"
bench_flag --python_points PYTHON_POINTS both "read_points | numpy | both"
bench_flag --python_max_bytes PYTHON_MAX_BYTES 0 "read_points on a prefix carrying N bytes of point data only (0 = whole bag)"
bench_flag --ros2 ROS2 1 "the MCAP and sqlite3 rows (0|1)"
bench_flag --ros2_large ROS2_LARGE 1 "also the large bag as MCAP (zstd chunks), for the memory of the MCAP path against the bag size (0|1)"
bench_flag --split_parts SPLIT_PARTS 4 "the small bag split by time into N bags in one folder, decoded as one sequence (0 = no split row)"
bench_switch --clean CLEAN "delete the generated bags of --scratch at the end"
bench_parse "$@"

DEBIAN_PYTHON=/usr/bin/python3
BENCH_DIR="$REPO/bench/decode"
WORK="$SCRATCH/tiltcal_decode_bench"
# One directory per run (logs and the decode output), so that two runs at
# the same time do not clobber each other; the bags are shared.
RUN_DIR="$WORK/run-$(date -u +%Y%m%dT%H%M%S)-$$"
LOGS="$RUN_DIR/logs"
mkdir -p "$LOGS"
log() { echo "run_decode_bench: $*" >&2; }

# ---- Packages: build deps of the project, plus the benchmark's extras. ----
"$REPO/scripts/setup.sh"
apt_install() {  # best effort; returns non-zero when a package is unavailable
  local missing=()
  for package in "$@"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
      missing+=("$package")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  log "installing ${missing[*]}"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null 2>&1 ||
    { $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq \
        --no-install-recommends "${missing[@]}" >/dev/null 2>&1; }
}
apt_install time
HAVE_ROS_CPP=1
apt_install librosbag-storage-dev libsensor-msgs-dev ||
  { HAVE_ROS_CPP=0; log "C++ rosbag library not installable: no C++ anchor"; }

# ---- Build (Release). ----
# A new build directory is configured without tests (not needed here, and a
# test directory being edited by someone else must not stop the benchmark);
# an existing one (e.g. --build_dir build) keeps its own settings, so that
# the benchmark does not turn the tests of a developer's build off.
TESTS_OPTION=()
[ -f "$BUILD_DIR/CMakeCache.txt" ] || TESTS_OPTION=(-DTILTCAL_BUILD_TESTS=OFF)
if ! cmake -S "$REPO" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    "${TESTS_OPTION[@]}" >"$LOGS/cmake.log" 2>&1; then
  log "cmake configure failed, see $LOGS/cmake.log"
  grep -A3 'CMake Error' "$LOGS/cmake.log" >&2 || true
  exit 1
fi
HAVE_DECODE=1
if ! cmake --build "$BUILD_DIR" --target tiltcal_decode -j2 >"$LOGS/build_decode.log" 2>&1; then
  HAVE_DECODE=0
  log "building tiltcal_decode failed (see $LOGS/build_decode.log); measuring the anchors only"
  tail -5 "$LOGS/build_decode.log" >&2
fi
DECODE="$BUILD_DIR/bin/tiltcal_decode"
CPP_READER="$BUILD_DIR/bin/tiltcal_bench_rosbag_cpp_reader"
if [ $HAVE_ROS_CPP = 1 ]; then
  if ! cmake --build "$BUILD_DIR" --target tiltcal_bench_rosbag_cpp_reader -j2 \
      >"$LOGS/build_cpp_reader.log" 2>&1; then
    HAVE_ROS_CPP=0
    log "C++ rosbag reader did not build (see $LOGS/build_cpp_reader.log): no C++ anchor"
  fi
fi

# ---- Bags (reused when present with their .meta). ----
need_gb=$(awk -v a="$SIZE_GB" -v b="$SMALL_GB" 'BEGIN { printf "%d", (2 * a + 2 * b + 1) * 1e9 }')
avail=$(df -B1 --output=avail "$SCRATCH" | tail -1)
make_bag() {  # SIZE_GB -> path on stdout
  local bag="$WORK/vlp16_lz4_${1}gb.bag"
  if [ ! -f "$bag" ] || [ ! -f "$bag.meta" ]; then
    if [ "$avail" -lt "$need_gb" ]; then
      log "not enough space in $SCRATCH ($avail bytes free, want $need_gb for bags and outputs)"
      exit 1
    fi
    log "generating $bag"
    "$DEBIAN_PYTHON" "$BENCH_DIR/make_vlp16_bag.py" --out "$bag" --size_gb "$1" \
      2>"$LOGS/make_bag_${1}gb.log" >&2
    tail -1 "$LOGS/make_bag_${1}gb.log" >&2
  else
    log "reusing $bag"
  fi
  echo "$bag"
}
BAG=$(make_bag "$SIZE_GB")
SMALL_BAG=$(make_bag "$SMALL_GB")
meta() { sed -n "s/^$2=//p" "$1.meta"; }

# ---- Timed runs. ----
# Results, one line per run: label bag wall_s max_rss_kb points_read exit cpu_s steal_s
RESULTS="$LOGS/results.txt"
: >"$RESULTS"
# CPU time the hypervisor gave other guests since boot, USER_HZ ticks
# (/proc/stat, field 9 of the cpu line): on a shared VM a run that lost
# seconds to steal has a long wall time for that reason alone.
steal_ticks() { awk '/^cpu / {print $9}' /proc/stat; }
TICKS_PER_S=$(getconf CLK_TCK)
# run_timed LABEL BAG POINTS_READ_CMD|- CMD...   (POINTS_READ "-" = all points of BAG)
run_timed() {
  local label=$1 bag=$2 i=$3
  shift 3
  local tag
  tag="$label.$(basename "$bag" .bag).$i"
  local tlog="$LOGS/$tag.time" out="$LOGS/$tag.out"
  local status=0 steal_before
  steal_before=$(steal_ticks)
  /usr/bin/time -v -o "$tlog" "$@" >"$out" 2>&1 || status=$?
  local steal
  steal=$(awk -v a="$steal_before" -v b="$(steal_ticks)" -v hz="$TICKS_PER_S" \
    'BEGIN { printf "%.2f", (b - a) / hz }')
  local wall rss
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, p, ":"); s = 0;
           for (k = 1; k <= n; ++k) s = s * 60 + p[k]; print s }' "$tlog")
  rss=$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$tlog")
  local cpu
  cpu=$(awk -F': ' '/User time \(seconds\)|System time \(seconds\)/ { s += $2 } END { print s }' "$tlog")
  local points
  points=$(sed -n 's/.* points=\([0-9]*\).*/\1/p' "$out" | tail -1)
  [ -z "$points" ] && points=$(meta "$bag" points)
  echo "$label $bag $wall $rss $points $status $cpu $steal" >>"$RESULTS"
  if [ $status -ne 0 ]; then
    log "$label failed (exit $status), output in $out:"
    tail -5 "$out" >&2
  fi
  return 0
}
warm() { cat "$1" >/dev/null; }

PARAMS="$REPO/stages/decode/default_params.txtpb"
run_decode() {  # LABEL BAG REPEAT
  local outdir="$RUN_DIR/out"
  mkdir -p "$outdir"
  run_timed "$1" "$2" "$3" "$DECODE" --bag="$2" --params="$PARAMS" \
    --out_imu="$outdir/imu.binpb" --out_scans="$outdir/scans.binpb.lz4"
  ls -l "$outdir" >>"$LOGS/$1.$(basename "$2" .bag).$3.out" 2>&1 || true
  rm -rf "$outdir"
}

LOAD_BEFORE=$(cut -d' ' -f1-3 /proc/loadavg)
warm "$BAG"
for ((r = 1; r <= REPEATS; ++r)); do
  log "run $r/$REPEATS on $(basename "$BAG")"
  [ $HAVE_DECODE = 1 ] && run_decode tiltcal_decode "$BAG" "$r"
  if [ $HAVE_ROS_CPP = 1 ]; then
    run_timed rosbag_cpp "$BAG" "$r" "$CPP_READER" "$BAG"
    # The same reader writing what it reads (rosbag_cpp_reader.cc, --out).
    mkdir -p "$RUN_DIR/out"
    run_timed rosbag_cpp_write "$BAG" "$r" "$CPP_READER" --out="$RUN_DIR/out/points.bin" "$BAG"
    rm -rf "$RUN_DIR/out"
  fi
done
if [ "$PYTHON_POINTS" = read_points ] || [ "$PYTHON_POINTS" = both ]; then
  log "python read_points on $(basename "$BAG")"
  run_timed rosbag_python_read_points "$BAG" 1 "$DEBIAN_PYTHON" \
    "$BENCH_DIR/rosbag_python_reader.py" --points=read_points \
    --max_bytes="$PYTHON_MAX_BYTES" "$BAG"
fi
if [ "$PYTHON_POINTS" = numpy ] || [ "$PYTHON_POINTS" = both ]; then
  log "python numpy on $(basename "$BAG")"
  run_timed rosbag_python_numpy "$BAG" 1 "$DEBIAN_PYTHON" \
    "$BENCH_DIR/rosbag_python_reader.py" --points=numpy "$BAG"
fi
warm "$SMALL_BAG"
for ((r = 1; r <= REPEATS && HAVE_DECODE; ++r)); do
  log "run $r/$REPEATS on $(basename "$SMALL_BAG")"
  run_decode tiltcal_decode "$SMALL_BAG" "$r"
done

# ---- Split row: the small bag as N bags split by record time. ----
# python3-rosbag copies the messages raw (tests/oracle/split_ros1_bag.py,
# lz4 chunks as the bag); decode reads the folder as one sequence, merging
# the files in record time.
if [ "$SPLIT_PARTS" -gt 1 ] && [ $HAVE_DECODE = 1 ]; then
  split_dir="$WORK/$(basename "$SMALL_BAG" .bag)_lz4_split$SPLIT_PARTS"
  if [ ! -f "$split_dir.meta" ]; then
    log "splitting $(basename "$SMALL_BAG") into $SPLIT_PARTS bags"
    rm -rf "$split_dir"
    "$DEBIAN_PYTHON" "$REPO/tests/oracle/split_ros1_bag.py" "$SMALL_BAG" "$split_dir" \
      --by=time --parts="$SPLIT_PARTS" --compression=lz4 >"$LOGS/split.log" 2>&1 &&
      cp "$SMALL_BAG.meta" "$split_dir.meta" || log "splitting failed: no split row"
  else
    log "reusing $split_dir"
  fi
  if [ -f "$split_dir.meta" ]; then
    cat "$split_dir"/*.bag >/dev/null
    for ((r = 1; r <= REPEATS; ++r)); do
      log "run $r/$REPEATS on $(basename "$split_dir")/"
      run_decode "tiltcal_decode_split$SPLIT_PARTS" "$split_dir" "$r"
    done
  fi
fi

# ---- ROS 2 rows: the small bag as MCAP and as a rosbag2 .db3. ----
# The same messages (python3-rosbag reads them, the npm libraries write
# them), so the rows compare the formats; the converted files are reused
# like the bags, with a copy of the bag's .meta. The messages go from the
# reader to the writer through a pipe (no JSON file on disk).
ros2_convert() {  # FORMAT OUT SOURCE_BAG [COMPRESSION]
  if [ -e "$2" ] && [ -f "$2.meta" ]; then log "reusing $2"; return 0; fi
  log "writing $2 from $(basename "$3")"
  local to_jsonl=("$DEBIAN_PYTHON" "$REPO/tests/oracle/ros1_bag_to_ros2_jsonl.py" "$3")
  if [ "$1" = mcap ]; then
    "${to_jsonl[@]}" | node "$REPO/tests/oracle/write_ros2_bags.mjs" "$2" --format=mcap \
      --compression="${4:-lz4}" --messages=/dev/stdin || return 1
  else
    "${to_jsonl[@]}" | node "$REPO/tests/oracle/write_ros2_bags.mjs" "$2.dir" --format=sqlite3 \
      --messages=/dev/stdin && mv "$2.dir/$(basename "$2").dir_0.db3" "$2" && rm -rf "$2.dir" ||
      return 1
  fi
  cp "$3.meta" "$2.meta"
}
if [ "$ROS2" = 1 ] && [ $HAVE_DECODE = 1 ]; then
  if [ -f "$REPO/tests/node_modules/@mcap/core/package.json" ] && command -v node >/dev/null; then
    small_base="$WORK/$(basename "$SMALL_BAG" .bag)"
    for format in mcap db3; do
      ros2_bag="$small_base.$format"
      if ros2_convert "$format" "$ros2_bag" "$SMALL_BAG"; then
        warm "$ros2_bag"
        for ((r = 1; r <= REPEATS; ++r)); do
          log "run $r/$REPEATS on $(basename "$ros2_bag")"
          run_decode "tiltcal_decode_$format" "$ros2_bag" "$r"
        done
      else
        log "could not convert the bag to $format: no $format row"
      fi
    done
    # The large bag as MCAP with zstd chunks (lz4js, the JavaScript lz4 of
    # the oracle, is slow on a GB): the MCAP path's memory against size.
    if [ "$ROS2_LARGE" = 1 ]; then
      large_mcap="$WORK/$(basename "$BAG" .bag).mcap"
      if ros2_convert mcap "$large_mcap" "$BAG" zstd; then
        warm "$large_mcap"
        for ((r = 1; r <= REPEATS; ++r)); do
          log "run $r/$REPEATS on $(basename "$large_mcap")"
          run_decode tiltcal_decode_mcap "$large_mcap" "$r"
        done
      else
        log "could not convert the large bag to MCAP: no large MCAP row"
      fi
    fi
  else
    log "no tests/node_modules (scripts/setup.sh) or node: no MCAP / sqlite3 rows"
  fi
fi

# ---- Table. ----
echo
echo "Decode benchmark, $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores," \
  "$(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -1)"
for b in "$BAG" "$SMALL_BAG"; do
  echo "  $(basename "$b"): $(meta "$b" bytes) bytes, $(meta "$b" clouds) clouds," \
    "$(meta "$b" points) points, $(meta "$b" imu) imu messages"
done
echo "  MB = 1e6 bytes of the bag file; median wall and cpu (user + sys) of $REPEATS runs for"
echo "  tiltcal_decode and the C++ reader, largest peak RSS; vs C++ = C++ rosbag wall / tool wall"
echo "  on the same bag (> 1: faster than the C++ rosbag library); cpu vs = the same on cpu s;"
echo "  rw vs and rw cpu = the same against rosbag_cpp_write (the C++ reader writing the points"
echo "  and IMU samples it reads to one file through stdio, no checksum, no fsync);"
echo "  steal s = CPU time the host gave other guests during the row's runs, summed."
echo "  Load average before the runs: $LOAD_BEFORE, after: $(cut -d' ' -f1-3 /proc/loadavg)"
awk -v big="$BAG" '
  # anchor / tool as "N.NNx" ("-" when either is missing or not on the big bag).
  function ratio(anchor_s, tool_s) {
    return (on_big && anchor_s > 0 && tool_s > 0) ? sprintf("%.2fx", anchor_s / tool_s) : "-"
  }
  function median(list, n,   a, i, j, t) {
    n = split(list, a, " ")
    for (i = 1; i <= n; ++i) for (j = i + 1; j <= n; ++j) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
    return (n % 2) ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
  }
  {
    key = $1 SUBSEP $2
    if (!(key in walls)) { order[++n] = key }
    walls[key] = walls[key] " " $3
    cpus[key] = cpus[key] " " $7
    steal[key] += $8
    if ($4 > rss[key]) rss[key] = $4
    points[key] = $5
    if ($6 != 0) failed[key] = 1
  }
  END {
    printf "\n%-40s %-25s %7s %7s %7s %9s %7s %7s %7s %7s %7s %7s\n", "tool", "bag", "wall s", "cpu s", "MB/s", "Mpoints/s", "RSS MB", "vs C++", "cpu vs", "rw vs", "rw cpu", "steal s"
    anchor_key = "rosbag_cpp" SUBSEP big
    anchor = (anchor_key in walls) ? median(walls[anchor_key]) : 0
    anchor_cpu = (anchor_key in cpus) ? median(cpus[anchor_key]) : 0
    rw_key = "rosbag_cpp_write" SUBSEP big
    rw = (rw_key in walls) ? median(walls[rw_key]) : 0
    rw_cpu = (rw_key in cpus) ? median(cpus[rw_key]) : 0
    for (k = 1; k <= n; ++k) {
      key = order[k]; split(key, parts, SUBSEP)
      w = median(walls[key])
      cmd = "du -sb " parts[2]; cmd | getline size; close(cmd); size += 0  # a file or a folder
      name = parts[1]
      if (failed[key]) name = name " (FAILED)"
      c = median(cpus[key])
      bn = parts[2]; sub(".*/", "", bn)
      # A prefix run (python read_points with --python_max_bytes) reads only
      # part of the bag: MB/s and the ratios are scaled by the fraction of
      # points it read.
      cmd = "sed -n s/^points=//p " parts[2] ".meta"; cmd | getline total; close(cmd)
      frac = (total > 0) ? points[key] / total : 1
      if (frac < 0.999) name = name sprintf(" [%.0f%% prefix]", 100 * frac)
      on_big = (parts[2] == big)
      printf "%-40s %-25s %7.2f %7.2f %7.1f %9.2f %7.1f %7s %7s %7s %7s %7.2f\n", name, bn, w, c,
             (w > 0 ? size * frac / w / 1e6 : 0), (w > 0 ? points[key] / w / 1e6 : 0), rss[key] / 1024,
             ratio(anchor * frac, w), ratio(anchor_cpu * frac, c), ratio(rw * frac, w),
             ratio(rw_cpu * frac, c), steal[key]
    }
  }' "$RESULTS" | tee "$LOGS/table.txt"
echo
log "logs in $LOGS"

status=0
[ $HAVE_DECODE = 1 ] || status=1
awk '$6 != 0 { bad = 1 } END { exit bad }' "$RESULTS" || status=1
if [ $CLEAN = 1 ]; then
  rm -f "$BAG" "$BAG.meta" "$SMALL_BAG" "$SMALL_BAG.meta"
  small_base="$WORK/$(basename "$SMALL_BAG" .bag)"
  rm -f "$small_base".{mcap,db3}{,.meta} "$WORK/$(basename "$BAG" .bag)".mcap{,.meta}
  rm -rf "$small_base"_split*
  log "removed the generated bags"
fi
exit $status
