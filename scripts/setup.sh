#!/usr/bin/env bash
# Installs every build and test dependency of tiltcal from Debian packages.
# Idempotent: does nothing when everything is present. Needs root (or sudo).
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libceres-dev libgoogle-glog-dev
  libpcl-dev libprotobuf-dev protobuf-compiler
  liblz4-dev lz4 libbz2-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-rosbag python3-sensor-msgs python3-numpy python3-matplotlib python3-yaml
  chromium
)

missing=()
for package in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
    missing+=("$package")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done" >&2
