#!/usr/bin/env bash
# Installs every build and test dependency of tiltcal from Debian packages
# (PCL's headers from libpcl-dev unpacked, not installed: see PCL_PACKAGES),
# then the test oracles of tests/package.json (npm ci into tests/node_modules).
# Idempotent: does nothing when everything is present. Needs root (or sudo)
# for the Debian packages.
#   setup.sh                build and test dependencies
#   setup.sh --build_only   only what the Release build needs (compilers,
#                           libraries, GoogleTest)
#   setup.sh --parsers_only only what the sanitizer build of the parsers
#                           needs (clang, protobuf, the compression
#                           libraries; no Ceres, no PCL): scripts/test.sh
#                           compiles it while the rest installs
#   setup.sh --cluster      and Slurm + munge, for the one-node cluster of
#                           scripts/slurm_local_cluster.sh (test pipeline.slurm)
set -euo pipefail

CLUSTER=0
ONLY=
for arg in "$@"; do
  case "$arg" in
    --cluster) CLUSTER=1 ;;
    --build_only | --parsers_only) ONLY=$arg ;;
    *) echo "usage: setup.sh [--build_only | --parsers_only] [--cluster]" >&2; exit 2 ;;
  esac
done

# What the parsers and their tests need to build (TILTCAL_PARSERS_ONLY).
PARSER_PACKAGES=(
  build-essential cmake ninja-build lld pkg-config git
  libeigen3-dev libprotobuf-dev protobuf-compiler
  liblz4-dev lz4 libbz2-dev libfmt-dev libsqlite3-dev libzstd-dev zlib1g-dev libpng-dev
  libgtest-dev libgmock-dev
)
# The PCL libraries the calibrator and its tests link, and what PCL's CMake
# package looks for (FLANN, five Boost libraries). Not libpcl-dev: it
# depends on all of PCL, VTK, Qt and Boost (about 330 packages more, 90 s
# of install on 2 cores); scripts/unpack_pcl_dev.sh unpacks its headers
# and CMake package into /opt/tiltcal/libpcl-dev instead, unless it is
# installed. The headers must match these libraries' version, Debian
# bookworm's PCL 1.13.
PCL_PACKAGES=(
  libpcl-common1.13 libpcl-kdtree1.13 libpcl-octree1.13 libpcl-search1.13
  libpcl-sample-consensus1.13 libpcl-filters1.13 libpcl-features1.13 libpcl-registration1.13
  libpcl-io1.13 libflann-dev
  libboost-system-dev libboost-filesystem-dev libboost-date-time-dev libboost-iostreams-dev
  libboost-serialization-dev
)
# The rest of what cmake and the Release build (tests and benchmarks
# included) need: the calibrator's libraries.
CALIBRATOR_PACKAGES=(libceres-dev libgoogle-glog-dev "${PCL_PACKAGES[@]}" libnanoflann-dev
                     libbenchmark-dev)
# clang with its sanitizer runtimes (scripts/sanitize_and_fuzz.sh).
CLANG_PACKAGES=(clang libclang-rt-14-dev)
# What only the tests run: the ROS 1 oracles and the browser of the report
# page's tests.
# python3-munkres answers matplotlib's python3-fonttools, which depends on
# "python3-scipy | python3-munkres": apt would otherwise take SciPy (and
# Pythran, 9 packages, 67 MB, a long byte-compile) that nothing here uses.
TEST_PACKAGES=(
  python3-rosbag python3-sensor-msgs python3-tf2 python3-numpy python3-matplotlib python3-yaml
  python3-munkres chromium
)
case $ONLY in
  --parsers_only) PACKAGES=("${PARSER_PACKAGES[@]}" "${CLANG_PACKAGES[@]}") ;;
  --build_only) PACKAGES=("${PARSER_PACKAGES[@]}" "${CALIBRATOR_PACKAGES[@]}") ;;
  *)
    PACKAGES=("${PARSER_PACKAGES[@]}" "${CALIBRATOR_PACKAGES[@]}" "${CLANG_PACKAGES[@]}"
              "${TEST_PACKAGES[@]}")
    ;;
esac
# Slurm's controller, node daemon and client commands, and munge (its
# authentication). Their services are not started here:
# scripts/slurm_local_cluster.sh runs the daemons itself.
if [ "$CLUSTER" = 1 ]; then
  PACKAGES+=(slurmctld slurmd slurm-client munge)
fi

# One dpkg-query for all of them (one per package took seconds on a loaded
# machine).
installed=$(dpkg-query -W -f='${Package} ${Status}\n' "${PACKAGES[@]}" 2>/dev/null |
  awk '$2 == "install" && $3 == "ok" && $4 == "installed" { print $1 }' || true)
missing=()
for package in "${PACKAGES[@]}"; do
  grep -qxF "$package" <<< "$installed" || missing+=("$package")
done
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if [ ${#missing[@]} -ne 0 ]; then
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  # dpkg without an fsync per unpacked file (its own database is still
  # synced), as in Debian's container images: a fresh machine unpacks about
  # 230 packages. A crash in the middle can leave some files empty;
  # apt-get install --reinstall mends them.
  $SUDO apt-get install -y -qq --no-install-recommends -o Dpkg::Options::=--force-unsafe-io \
    "${missing[@]}" >/dev/null
  echo "setup: Debian packages done" >&2
fi
# PCL's headers and CMake package, without libpcl-dev's dependencies
# (sudo only when they are missing or of another version).
unpack_pcl_dev=$(dirname "${BASH_SOURCE[0]}")/unpack_pcl_dev.sh
if [ "$ONLY" != --parsers_only ] && ! "$unpack_pcl_dev" --check; then
  $SUDO "$unpack_pcl_dev"
fi

# The npm packages of the ROS 2 test oracles (tests/oracle/write_ros2_bags.mjs),
# pinned by tests/package-lock.json; all are JavaScript or WebAssembly (sql.js
# for the rosbag2 sqlite3 files), nothing is compiled. npm ci only when the
# lock file differs from the one of the last install (its sha256 is kept in
# node_modules/.tiltcal-lock.sha256). A node_modules that is a symlink (a git
# worktree sharing another checkout's) is replaced by the worktree's own
# install instead of being emptied through the link. The build needs none of
# them.
[ -n "$ONLY" ] && exit 0
TESTS_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/../tests" && pwd)"
if ! command -v npm >/dev/null; then
  echo "setup: no npm (Node 20): the ROS 2 bag tests will be skipped" >&2
else
  lock_sum=$(sha256sum < "$TESTS_DIR/package-lock.json")
  stamp=$TESTS_DIR/node_modules/.tiltcal-lock.sha256
  if [ "$(cat "$stamp" 2>/dev/null)" != "$lock_sum" ]; then
    echo "setup: npm ci in $TESTS_DIR" >&2
    if [ -L "$TESTS_DIR/node_modules" ]; then rm "$TESTS_DIR/node_modules"; fi
    (cd "$TESTS_DIR" && npm ci --no-audit --no-fund --loglevel=error)
    echo "$lock_sum" > "$stamp"
  fi
fi
