#!/usr/bin/env bash
# Unpacks Debian's libpcl-dev (PCL's headers, its CMake package and the .so
# links) into a prefix, without installing the package's dependencies.
# libpcl-dev depends on every PCL library, VTK, Qt, OpenNI and the whole of
# Boost, for PCL's viewers and grabbers: about 330 packages (0.8 GB), which
# tiltcal does not use. The PCL libraries tiltcal links come from their own
# packages (PCL_PACKAGES in scripts/setup.sh, which calls this). In the
# prefix, each .so link points at the installed library of the same
# version, and the links to libraries that are not installed are removed,
# so that CMake finds only those. The top CMakeLists.txt searches the
# prefix after the system's paths: where libpcl-dev is installed, it is
# found first, and this does nothing.
#   unpack_pcl_dev.sh [--check] [PREFIX]   default /opt/tiltcal/libpcl-dev
# Idempotent: does nothing when libpcl-dev is installed or PREFIX holds the
# version of the installed libpcl-common; --check only tells whether there
# is nothing to do (exit 0) or not (1), and needs no write access. PREFIX
# is unpacked beside itself and then renamed into place, so a failure
# leaves the old one whole. Needs write access to PREFIX's parent and apt's
# package lists.
set -euo pipefail
CHECK=0
if [ "${1:-}" = --check ]; then CHECK=1; shift; fi
PREFIX=${1:-/opt/tiltcal/libpcl-dev}

# The version of the first installed package matching $1; empty if none.
installed_version() {
  dpkg-query -W -f='${db:Status-Abbrev} ${Version}\n' "$1" 2>/dev/null |
    awk '$1 == "ii" { print $2; exit }' || true
}
[ -z "$(installed_version libpcl-dev)" ] || exit 0
version=$(installed_version 'libpcl-common*')
if [ -z "$version" ]; then
  echo "unpack_pcl_dev.sh: libpcl-common is not installed (scripts/setup.sh installs it)" >&2
  exit 1
fi
[ "$(cat "$PREFIX/tiltcal-version" 2>/dev/null)" != "$version" ] || exit 0
[ "$CHECK" = 0 ] || exit 1

mkdir -p "$(dirname "$PREFIX")"
work=$(mktemp -d "$(dirname "$PREFIX")/.libpcl-dev.XXXXXX")
trap 'rm -rf "$work"' EXIT
download() {
  (cd "$work" && apt-get download -qq -o APT::Sandbox::User=root "libpcl-dev=$version")
}
# Stale or absent package lists: update them once and retry.
if ! download 2>/dev/null && ! { apt-get update -qq && download; }; then
  echo "unpack_pcl_dev.sh: apt-get download libpcl-dev=$version failed" >&2
  exit 1
fi
dpkg-deb -x "$work"/libpcl-dev_*.deb "$work/root"

multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH)
for link in "$work/root/usr/lib/$multiarch"/libpcl_*.so; do
  library=/usr/lib/$multiarch/$(readlink "$link")
  if [ -e "$library" ]; then ln -sfn "$library" "$link"; else rm "$link"; fi
done
echo "$version" > "$work/root/usr/tiltcal-version"

rm -rf "$PREFIX.old"
[ ! -e "$PREFIX" ] || mv "$PREFIX" "$PREFIX.old"
mv "$work/root/usr" "$PREFIX"
rm -rf "$PREFIX.old"
echo "unpack_pcl_dev.sh: libpcl-dev $version in $PREFIX" >&2
