#!/usr/bin/env bash
# The starting extrinsic from the motion, measured: one 40 s Husky-like
# sequence (IMU upside down), flat and tilted (8 deg pitch, 3 deg roll, g_f
# from the flat sequence run with the measured rig), each calibrated by
# `make -f Makefile.pipeline` as a one-bag dataset with these rigs:
#   measured      the simulator's rig file (rotation 1.7 deg, translation 4.5 cm off)
#   none          no imu_from_lidar
#   identity      imu_from_lidar rotation = identity
#   yaw90         the true rotation turned 90 deg about the IMU's z
#   x180          the true rotation turned 180 deg about the IMU's x
#   tf_static     no imu_from_lidar; the bag's /tf_static has the true extrinsic
#   tf_static_off no imu_from_lidar; the bag's /tf_static is 2 deg and 5 cm off
#   inspect_rig   the rig `tiltcal_inspect rig` drafts from the bag with /tf_static,
#                 imu_height_m filled in
# Prints one row per case: exit code, verdict, rotation (deg), translation
# per axis (mm) and tau (ms) errors against the truth, seconds of make.
#   bench/initial_extrinsic/rig_faults.sh [--build_dir=DIR] [--scratch=DIR] [--seed=N]
set -euo pipefail
. "$(dirname "$0")/../common.sh"
SRC=$REPO
bench_flag --seed SEED 105 "simulator seed"
bench_parse "$@"
require_binaries tiltcal_simulate tiltcal_initial_extrinsic tiltcal_inspect tiltcal_calibrate
PY=/usr/bin/python3

# scenario KIND TF_STATIC_BLOCK: the demo's Husky scenario, flat or tilted.
scenario() {
  local kind=$1 tf=$2
  local pitch=0 roll=0
  [ "$kind" = tilted ] && { pitch=8; roll=3; }
  sed -E -e "s/^seed: .*/seed: $SEED/" -e "s/^duration_s: .*/duration_s: 40/" \
    -e "s/^ground_pitch_deg: .*/ground_pitch_deg: $pitch/" \
    -e "s/^ground_roll_deg: .*/ground_roll_deg: $roll/" \
    "$SRC/stages/simulate/scenarios/tilted_husky_vlp16.txtpb"
  echo "$tf"
}

TF_TRUE='tf_static { write: true }'
TF_OFF='tf_static { write: true lidar_rotation_error_deg { x: 1.2 y: -1.2 z: 1.0 } lidar_translation_error_m { x: 0.03 y: -0.03 z: 0.025 } }'
for kind in flat tilted; do
  for tf in plain tf_true tf_off; do
    block=""
    [ $tf = tf_true ] && block=$TF_TRUE
    [ $tf = tf_off ] && block=$TF_OFF
    scenario $kind "$block" > "$SCRATCH/$kind.$tf.scenario.txtpb"
    "$BIN/tiltcal_simulate" --params="$SCRATCH/$kind.$tf.scenario.txtpb" \
      --out_bag="$SCRATCH/$kind.$tf.bag" --out_truth="$SCRATCH/$kind.$tf.truth.txtpb" \
      --out_rig="$SCRATCH/$kind.$tf.rig.txtpb" 2> /dev/null
  done
done

# rig CASE KIND > rig.txtpb
rig() {
  "$PY" - "$1" "$SCRATCH/$2.plain.rig.txtpb" "$SCRATCH/$2.plain.truth.txtpb" <<'PYEOF'
import re, sys, math
import numpy as np
case, rig_path, truth_path = sys.argv[1:]
rig = open(rig_path).read()
truth = open(truth_path).read()
def block(text, name):
    i = text.index(name + ' {')
    depth, j = 0, i
    while True:
        if text[j] == '{': depth += 1
        if text[j] == '}':
            depth -= 1
            if depth == 0: return text[i:j + 1]
        j += 1
def field(b, sub, k):
    m = re.search(sub + r' \{[^}]*?\b' + k + r': (-?[\d.e+-]+)', b)
    return float(m.group(1)) if m else 0.0
t = block(truth, 'imu_from_lidar')
q = np.array([field(t, 'rotation', k) for k in 'wxyz'])
r = [field(t, 'translation', k) for k in 'xyz']
def mul(a, b):
    w1, x1, y1, z1 = a; w2, x2, y2, z2 = b
    return np.array([w1*w2-x1*x2-y1*y2-z1*z2, w1*x2+x1*w2+y1*z2-z1*y2,
                     w1*y2-x1*z2+y1*w2+z1*x2, w1*z2+x1*y2-y1*x2+z1*w2])
def turn(axis, deg):
    a = math.radians(deg) / 2
    return np.array([math.cos(a)] + [math.sin(a) * c for c in axis])
rest = rig.replace(block(rig, 'imu_from_lidar'), '').strip() + '\n'
measured = block(rig, 'imu_from_lidar')
mr = [field(measured, 'translation', k) for k in 'xyz']
def with_rotation(qq):
    return ('imu_from_lidar {\n  rotation { w: %r x: %r y: %r z: %r }\n'
            '  translation { x: %r y: %r z: %r }\n}\n' % (*qq, *mr)) + rest
if case in ('measured',): print(rig, end='')
elif case in ('none', 'tf_static', 'tf_static_off'): print(rest, end='')
elif case == 'identity': print(with_rotation([1.0, 0.0, 0.0, 0.0]), end='')
elif case == 'yaw90': print(with_rotation(mul(turn((0, 0, 1), 90), q)), end='')
elif case == 'x180': print(with_rotation(mul(turn((1, 0, 0), 180), q)), end='')
PYEOF
}

# errors CALIBRATION TRUTH: rotation deg, translation mm per axis, tau ms
errors() {
  "$PY" - "$1" "$2" <<'PYEOF'
import re, sys, math
def read(p):
    t = open(p).read()
    i = t.index('imu_from_lidar {')
    b = t[i:i + 600]
    g = lambda s, k: float((re.search(s + r' \{[^}]*?\b' + k + r': (-?[\d.e+-]+)', b) or [0, 0])[1])
    q = [g('rotation', k) for k in 'wxyz']
    r = [g('translation', k) for k in 'xyz']
    tau = float(re.search(r'^time_offset_s: (-?[\d.e+-]+)', t, re.M).group(1))
    return q, r, tau
(q1, r1, t1), (q2, r2, t2) = read(sys.argv[1]), read(sys.argv[2])
d = abs(sum(a * b for a, b in zip(q1, q2)))
print('%.3f  %6.1f %6.1f %6.1f  %6.2f' % (2 * math.degrees(math.acos(min(1.0, d))),
      *[(a - b) * 1e3 for a, b in zip(r1, r2)], (t1 - t2) * 1e3))
PYEOF
}

# run NAME KIND BAG_KIND CASE [GRAVITY_REFERENCE]
run() {
  local name=$1 kind=$2 bag=$3 case=$4 ref=${5:-}
  local d=$SCRATCH/$name
  rm -rf "$d"; mkdir -p "$d"
  cp "$SCRATCH/$kind.$bag.bag" "$d/seq.bag"
  cp "$SCRATCH/$kind.$bag.truth.txtpb" "$d/seq.truth.txtpb"
  if [ "$case" = inspect_rig ]; then
    # The rig tiltcal_inspect rig drafts from the bag, with imu_height_m filled in.
    "$BIN/tiltcal_inspect" rig --bag="$d/seq.bag" --out="$d/draft.txtpb" 2> /dev/null
    sed 's/^# imu_height_m: 0.0$/imu_height_m: 0.3/' "$d/draft.txtpb" > "$d/rig.txtpb"
  else
    rig "$case" "$kind" | sed '/^gravity_reference:/d' > "$d/rig.txtpb"
  fi
  [ -n "$ref" ] && echo "gravity_reference: \"$ref\"" >> "$d/rig.txtpb"
  local start=$SECONDS rc=0
  make -s -f "$SRC/Makefile.pipeline" DATASET="$d" BIN="$BIN" > "$d/make.log" 2>&1 || rc=$?
  local cal=$d/out/seq/calibration.txtpb
  [ -f "$cal" ] || cal=$d/out/seq/calibration.suspect.txtpb
  if [ -f "$cal" ]; then
    printf '%-8s %-14s rc %d  %-8s %s  %3d s\n' "$kind" "$case" "$rc" \
      "$(sed -n 's/^verdict: //p' "$cal")" "$(errors "$cal" "$d/seq.truth.txtpb")" $((SECONDS - start))
  else
    printf '%-8s %-14s rc %d  no calibration: %s\n' "$kind" "$case" "$rc" \
      "$(grep -m1 -E 'error|Error|refus' "$d/make.log" | cut -c1-160)"
  fi
}

echo "kind     rig            exit  verdict  rot_deg  dx_mm  dy_mm  dz_mm  tau_ms  make"
run flat_measured flat plain measured
for case in none identity yaw90 x180; do
  run flat_$case flat plain $case
  run tilted_$case tilted plain $case ../flat_measured
done
run tilted_measured tilted plain measured ../flat_measured
run flat_tf_static flat tf_true tf_static
run tilted_tf_static tilted tf_true tf_static ../flat_measured
run flat_inspect_rig flat tf_true inspect_rig
run tilted_inspect_rig tilted tf_true inspect_rig ../flat_measured
run flat_tf_static_off flat tf_off tf_static_off
run tilted_tf_static_off tilted tf_off tf_static_off ../flat_measured
for d in "$SCRATCH"/*_tf_static_off; do
  echo "$(basename "$d"): $(grep -h 'tf_static' "$d/out/seq/calibration.txtpb" 2>/dev/null | grep -m1 'verdict_notes' || true)"
done
