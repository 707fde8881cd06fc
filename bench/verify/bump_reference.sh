#!/usr/bin/env bash
# A calibration.txtpb with its extrinsic bumped, as a LiDAR knocked on its
# mount: C_bl' = Exp(theta) C_bl (theta about the IMU's axes, frame b),
# r' = r + delta (frame b), tau' = tau + delta_tau; everything else (the
# covariance included) as it was.
#   bench/verify/bump_reference.sh IN OUT ROT_X_DEG ROT_Y_DEG ROT_Z_DEG DX_M DY_M DZ_M DTAU_S
# (no binaries: --build_dir and --scratch are not used)
set -euo pipefail
. "$(dirname "$0")/../common.sh"
bench_args "IN OUT RX RY RZ DX DY DZ DTAU" "the calibration, the bumped one, the bump (deg, m, s)"
bench_parse "$@"
[ ${#BENCH_ARGS[@]} -eq 9 ] || bench_die "needs 9 arguments (see --help)"
set -- "${BENCH_ARGS[@]}"
in=$1 out=$2
awk -v rx="$3" -v ry="$4" -v rz="$5" -v dx="$6" -v dy="$7" -v dz="$8" -v dt="$9" '
  function num(v) { return sprintf("%.17g", v) }
  BEGIN { w = 1; x = 0; y = 0; z = 0; tx = 0; ty = 0; tz = 0; tau = 0 }
  /^imu_from_lidar \{$/ { block = 1; next }
  block && /^  rotation \{$/ { part = "r"; next }
  block && /^  translation \{$/ { part = "t"; next }
  block && /^    [wxyz]: / {
    k = substr($1, 1, 1)
    if (part == "r") { if (k == "w") w = $2; if (k == "x") x = $2; if (k == "y") y = $2; if (k == "z") z = $2 }
    else { if (k == "x") tx = $2; if (k == "y") ty = $2; if (k == "z") tz = $2 }
    next
  }
  block && /^}$/ { block = 0; next }
  block { next }
  /^time_offset_s: / { tau = $2; next }
  { rest[++n] = $0 }
  END {
    d2r = atan2(0, -1) / 180
    ax = rx * d2r; ay = ry * d2r; az = rz * d2r
    th = sqrt(ax * ax + ay * ay + az * az)
    if (th > 0) { s = sin(th / 2) / th; qw = cos(th / 2); qx = ax * s; qy = ay * s; qz = az * s }
    else { qw = 1; qx = 0; qy = 0; qz = 0 }
    nw = qw * w - qx * x - qy * y - qz * z
    nx = qw * x + qx * w + qy * z - qz * y
    ny = qw * y - qx * z + qy * w + qz * x
    nz = qw * z + qx * y - qy * x + qz * w
    print "imu_from_lidar {"
    print "  rotation {"
    print "    w: " num(nw); print "    x: " num(nx); print "    y: " num(ny); print "    z: " num(nz)
    print "  }"
    print "  translation {"
    print "    x: " num(tx + dx); print "    y: " num(ty + dy); print "    z: " num(tz + dz)
    print "  }"
    print "}"
    print "time_offset_s: " num(tau + dt)
    for (i = 1; i <= n; ++i) print rest[i]
  }' "$in" > "$out.tmp.$$"
mv -f -- "$out.tmp.$$" "$out"
