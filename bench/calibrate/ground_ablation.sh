#!/usr/bin/env bash
# Ground-residual ablation (docs/design.md §8): simulates a level and a tilted
# (8 deg pitch, 3 deg roll) sequence with the Husky-like rig, runs decode,
# ground and gravity once per sequence, then tiltcal_calibrate once per
# ground-residual set (params overrides: each residual forced ON or OFF), and
# prints the errors against the simulation truth: rotation (deg), translation
# per axis (cm), time offset (ms). Then the misinitialisation study: the same
# on the tilted sequence with the rig's r_b^{lb} off by [-0.6, 1.0, 0.6] m.
#
# The tilted sequence takes its flat-ground gravity g_f from the level run
# (rig gravity_reference -> level/gravity.txtpb), as a real dataset would.
#
# A set is residual names joined by "+"; a name with the suffix "L2" (e.g.
# "flatL2") is that residual without its robust loss (cauchy_scale 0), which
# shows what the Cauchy loss hides: the flat residual's bias on tilted ground.
#
# With --seeds "1 2 3", the whole study runs once per seed (in
# <scratch>/seed_<n>, tables printed as they come) and a last table gives
# the largest |error| of every row over the seeds.
#
#   bench/calibrate/ground_ablation.sh [--build_dir DIR]
#   bench/calibrate/ground_ablation.sh --scratch /tmp/ablation --duration_s 30 \
#     --seed 2 --sets "none dist" --misinit 0
#   bench/calibrate/ground_ablation.sh --seeds "1 2 3"
# The environment variables of the older form (ABLATION_DIR, ABLATION_SEED,
# ABLATION_SEEDS, ABLATION_DURATION_S, ABLATION_SETS, ABLATION_MISINIT,
# ABLATION_MISINIT_SETS) still give the defaults, and a BIN_DIR argument the
# binaries.
#
# Outputs in the scratch folder: the sequences, base_calibrate_params.txtpb (the
# defaults every run starts from, copied once), runs/<name>/{params,
# calibration,truth}.txtpb, errors.csv (tiltcal_report), table.txt (printed);
# with ABLATION_SEEDS also table_over_seeds.txt.
# Existing sequences and runs in --scratch DIR are reused.
set -euo pipefail
. "$(dirname "$0")/../common.sh"
ROOT=$REPO
bench_flag --duration_s DURATION_S "${ABLATION_DURATION_S:-30}" "sequence length, s"
bench_flag --seed SEED "${ABLATION_SEED:-1}" "simulator seed of both sequences (noise, world)"
bench_flag --seeds SEEDS "${ABLATION_SEEDS:-}" "run the study once per seed, then the worst case over them"
bench_flag --sets SETS "${ABLATION_SETS:-none flat flatL2 dist incl dist+incl dist+up flat+dist}" "residual sets"
bench_flag --misinit MISINIT "${ABLATION_MISINIT:-1}" "the misinitialisation study (0|1)"
bench_flag --misinit_sets MISINIT_SETS "${ABLATION_MISINIT_SETS:-none dist incl dist+incl dist+up}" "its residual sets"
bench_args "[BIN_DIR]" "the binaries (older form of --build_dir)"
[ -z "${ABLATION_DIR:-}" ] || SCRATCH=$ABLATION_DIR
bench_parse "$@"
[ ${#BENCH_ARGS[@]} -eq 0 ] || BIN=$(cd "${BENCH_ARGS[0]}" && pwd)
WORK=$SCRATCH
MISINIT_OFFSET=(-0.6 1.0 0.6)  # m, added to the rig's r_b^{lb}

if [ -n "$SEEDS" ]; then
  # One study per seed, then the worst case of every row over the seeds.
  tables=()
  for seed in $SEEDS; do
    "$0" --build_dir "$BUILD_DIR" --scratch "$WORK/seed_$seed" --seeds "" --seed "$seed" \
      --duration_s "$DURATION_S" --sets "$SETS" --misinit "$MISINIT" \
      --misinit_sets "$MISINIT_SETS" ${BENCH_ARGS[@]+"${BENCH_ARGS[@]}"}
    echo
    tables+=("$WORK/seed_$seed/table.txt")
  done
  {
    echo "Largest |error| of every row over seeds: $SEEDS"
    printf '%-8s %-11s %7s %7s %7s %8s %8s %8s %8s\n' sequence residuals rot_deg yaw_deg \
      tilt_deg dx_cm dy_cm dz_cm tau_ms
    awk 'function abs(v) { return v < 0 ? -v : v }
      $1 ~ /^(level|tilted|misinit)$/ && $3 ~ /^-?[0-9.]+$/ {
        key = $1 " " $2
        if (!(key in seen)) { seen[key] = 1; order[++n] = key }
        for (c = 3; c <= 9; ++c) if (abs($c) > worst[key, c]) worst[key, c] = abs($c)
      }
      END {
        for (i = 1; i <= n; ++i) {
          split(order[i], k, " ")
          printf "%-8s %-11s %7.3f %7.3f %7.3f %8.2f %8.2f %8.2f %8.3f\n", k[1], k[2],
                 worst[order[i], 3], worst[order[i], 4], worst[order[i], 5], worst[order[i], 6],
                 worst[order[i], 7], worst[order[i], 8], worst[order[i], 9]
        }
      }' "${tables[@]}"
  } | tee "$WORK/table_over_seeds.txt"
  exit 0
fi

require_binaries tiltcal_simulate tiltcal_decode tiltcal_ground tiltcal_gravity tiltcal_calibrate \
  tiltcal_report
log() { echo "ground_ablation: $*" >&2; }
# Every run starts from the same snapshot of the calibrate defaults.
[ -s "$WORK/base_calibrate_params.txtpb" ] ||
  cp "$ROOT/stages/calibrate/default_params.txtpb" "$WORK/base_calibrate_params.txtpb"

# --- sequences ----------------------------------------------------------------

prepare() {  # name base_scenario
  local name=$1 base=$2 dir=$WORK/$1
  if [ -s "$dir/gravity.txtpb" ]; then log "$name: reusing $dir"; return; fi
  mkdir -p "$dir"
  sed -E -e "s/^duration_s: .*/duration_s: $DURATION_S/" -e "s/^num_threads: .*/num_threads: 2/" \
    -e "s/^seed: .*/seed: $SEED/" \
    "$base" > "$dir/scenario.txtpb"
  log "$name: simulate ($DURATION_S s)"
  "$BIN/tiltcal_simulate" --quiet --params="$dir/scenario.txtpb" --out_bag="$dir/seq.bag" \
    --out_truth="$dir/truth.txtpb" --out_rig="$dir/rig.txtpb"
  if [ "$name" = tilted ]; then
    # g_f from the level run.
    sed -i -E '/^gravity_reference:/d' "$dir/rig.txtpb"
    echo 'gravity_reference: "../level/gravity.txtpb"' >> "$dir/rig.txtpb"
  fi
  log "$name: decode, ground, gravity"
  "$BIN/tiltcal_decode" --bag="$dir/seq.bag" --rig="$dir/rig.txtpb" \
    --params="$ROOT/stages/decode/default_params.txtpb" \
    --out_imu="$dir/imu.binpb" --out_scans="$dir/scans.binpb.lz4"
  "$BIN/tiltcal_ground" --imu="$dir/imu.binpb" --scans="$dir/scans.binpb.lz4" --rig="$dir/rig.txtpb" \
    --params="$ROOT/stages/ground/default_params.txtpb" --out_ground="$dir/ground.binpb"
  "$BIN/tiltcal_gravity" --imu="$dir/imu.binpb" --ground="$dir/ground.binpb" --rig="$dir/rig.txtpb" \
    --params="$ROOT/stages/gravity/default_params.txtpb" --out="$dir/gravity.txtpb"
}

# Calibrate params with every ground residual forced ON or OFF: "none",
# "flat", "dist+incl", ... Rewrites the mode of each residual's line of the
# default params (a field may not be given twice in text format).
write_params() {  # set out_file
  local set=$1 out=$2 script=()
  for r in flat dist incl up; do
    local mode=OFF
    [[ "+$set+" == *"+$r+"* || "+$set+" == *"+${r}L2+"* ]] && mode=ON
    script+=(-e "s/^( *)$r \\{ mode: [A-Z]+/\\1$r { mode: $mode/")
    [[ "+$set+" == *"+${r}L2+"* ]] && script+=(-e "/^ *$r \\{/s/cauchy_scale: [0-9.eE+-]+/cauchy_scale: 0/")
  done
  sed -E "${script[@]}" "$WORK/base_calibrate_params.txtpb" > "$out"
  for r in flat dist incl up; do
    grep -Eq "^ *$r \\{ mode: " "$out" || { log "no '$r { mode: ...' line in the default params"; exit 1; }
  done
}

# The rig with r_b^{lb} moved by MISINIT_OFFSET (the translation block of
# imu_from_lidar as written by tiltcal_simulate).
write_misinit_rig() {  # rig_in rig_out
  awk -v ox="${MISINIT_OFFSET[0]}" -v oy="${MISINIT_OFFSET[1]}" -v oz="${MISINIT_OFFSET[2]}" '
    /translation[[:space:]]*\{/ { in_t = 1 }
    in_t && match($0, /^[[:space:]]*[xyz]:/) {
      split($0, kv, ":"); key = kv[1]; gsub(/[[:space:]]/, "", key)
      v = kv[2] + (key == "x" ? ox : key == "y" ? oy : oz)
      sub(/:.*/, ": " sprintf("%.6f", v)); done[key] = 1
    }
    in_t && /\}/ { in_t = 0 }
    { print }
    END { if (!(done["x"] && done["y"] && done["z"])) exit 3 }' "$1" > "$2"
}

calibrate() {  # run_name sequence set rig
  local run=$1 seq=$2 set=$3 rig=$4 dir=$WORK/runs/$1 seqdir=$WORK/$2
  mkdir -p "$dir"
  if [ -s "$dir/calibration.txtpb" ]; then return; fi
  write_params "$set" "$dir/params.txtpb"
  local start=$SECONDS
  if ! "$BIN/tiltcal_calibrate" --quiet --imu="$seqdir/imu.binpb" --scans="$seqdir/scans.binpb.lz4" \
      --ground="$seqdir/ground.binpb" --gravity="$seqdir/gravity.txtpb" --rig="$rig" \
      --params="$dir/params.txtpb" --out="$dir/calibration.txtpb" 2> "$dir/stderr.txt"; then
    log "$run: calibrate failed: $(tail -1 "$dir/stderr.txt")"
    return
  fi
  echo $((SECONDS - start)) > "$dir/seconds.txt"
  cp "$seqdir/truth.txtpb" "$dir/truth.txtpb"
  log "$run: $((SECONDS - start)) s"
}

prepare level "$ROOT/stages/simulate/scenarios/flat_vlp16.txtpb"
prepare tilted "$ROOT/stages/simulate/scenarios/tilted_husky_vlp16.txtpb"
for f in level tilted; do
  log "$f: $(grep -E '^(is_level|level_statistic|has_gravity_flat):' "$WORK/$f/gravity.txtpb" | tr '\n' ' ')"
done

RUNS=()
for seq in level tilted; do
  for set in $SETS; do
    calibrate "${seq}__$set" "$seq" "$set" "$WORK/$seq/rig.txtpb"
    RUNS+=("${seq}__$set")
  done
done
if [ "$MISINIT" = 1 ]; then
  write_misinit_rig "$WORK/tilted/rig.txtpb" "$WORK/tilted/rig_misinit.txtpb"
  for set in $MISINIT_SETS; do
    calibrate "misinit__$set" tilted "$set" "$WORK/tilted/rig_misinit.txtpb"
    RUNS+=("misinit__$set")
  done
fi

# --- table --------------------------------------------------------------------

# Rotation error split about the ground normal: phi = Log(C_true^T C_est)
# (LiDAR frame), yaw = phi . n_l with n_l = C_true^T g~_f (the plane normal of
# a rigid vehicle, from the truth's g_f), tilt = |phi - yaw n_l|, in deg.
rotation_split() {  # calibration.txtpb truth.txtpb
  awk '
    function field(v) { sub(/^[^:]*:[[:space:]]*/, "", v); return v + 0 }
    FNR == 1 { file++; block = ""; depth = 0 }
    /^imu_from_lidar[[:space:]]*\{/ { block = "x"; depth = 1; next }
    /^gravity_flat_in_imu[[:space:]]*\{/ { block = "g"; depth = 1; next }
    block != "" && /\{/ { depth++; sub_block = $1; next }
    block != "" && /\}/ { depth--; if (depth == 0) block = ""; sub_block = ""; next }
    block == "x" && sub_block == "rotation" && /^[[:space:]]*[wxyz]:/ {
      k = $1; sub(/:/, "", k); q[file, k] = field($0)
    }
    block == "g" && /^[[:space:]]*[xyz]:/ { k = $1; sub(/:/, "", k); g[k] = field($0) }
    END {
      # e = conj(t) * c, t = truth (file 2), c = calibration (file 1).
      tw = q[2, "w"]; tx = -q[2, "x"]; ty = -q[2, "y"]; tz = -q[2, "z"]
      cw = q[1, "w"]; cx = q[1, "x"]; cy = q[1, "y"]; cz = q[1, "z"]
      ew = tw * cw - tx * cx - ty * cy - tz * cz
      ex = tw * cx + tx * cw + ty * cz - tz * cy
      ey = tw * cy - tx * cz + ty * cw + tz * cx
      ez = tw * cz + tx * cy - ty * cx + tz * cw
      if (ew < 0) { ew = -ew; ex = -ex; ey = -ey; ez = -ez }
      n = sqrt(ex * ex + ey * ey + ez * ez)
      a = n > 1e-15 ? 2 * atan2(n, ew) / n : 2
      px = a * ex; py = a * ey; pz = a * ez
      # n_b = -g_f / |g_f|, n_l = C_true^T n_b (rotate by conj(truth)).
      gn = sqrt(g["x"] ^ 2 + g["y"] ^ 2 + g["z"] ^ 2)
      bx = -g["x"] / gn; by = -g["y"] / gn; bz = -g["z"] / gn
      # v_l = R(t)^T v_b with t = (w, -x, -y, -z) already conjugated: R(conj) v.
      ux = tx; uy = ty; uz = tz
      cxv = uy * bz - uz * by; cyv = uz * bx - ux * bz; czv = ux * by - uy * bx
      lx = bx + 2 * (tw * cxv + uy * czv - uz * cyv)
      ly = by + 2 * (tw * cyv + uz * cxv - ux * czv)
      lz = bz + 2 * (tw * czv + ux * cyv - uy * cxv)
      yaw = px * lx + py * ly + pz * lz
      tx2 = px - yaw * lx; ty2 = py - yaw * ly; tz2 = pz - yaw * lz
      r2d = 180 / atan2(0, -1)
      printf "%.3f %.3f\n", yaw * r2d, sqrt(tx2 * tx2 + ty2 * ty2 + tz2 * tz2) * r2d
    }' "$1" "$2"
}

DIRS=()
for run in "${RUNS[@]}"; do
  [ -s "$WORK/runs/$run/calibration.txtpb" ] && DIRS+=("$WORK/runs/$run")
done
[ ${#DIRS[@]} -gt 0 ] || { log "no calibration succeeded"; exit 1; }
"$BIN/tiltcal_report" --out="$WORK/report.txt" --out_csv="$WORK/errors.csv" --title=ablation \
  "${DIRS[@]}" > /dev/null

{
  echo "Ground-residual ablation: ${DURATION_S} s Husky-like VLP-16 sequences (level; tilted 8 deg pitch, 3 deg roll), seed $SEED."
  echo "Errors = estimate - truth. misinit: tilted, rig r_b^{lb} off by [${MISINIT_OFFSET[*]}] m."
  echo "Measured rig (initial guess) is off by (0.5, -0.7, 1.5) deg and (2, -3, 2.5) cm."
  echo
  echo "rot = |Log(C_true^T C_est)|, split into yaw (about the ground normal) and tilt."
  echo
  printf '%-8s %-11s %7s %7s %7s %8s %8s %8s %8s %6s  %s\n' sequence residuals rot_deg \
    yaw_deg tilt_deg dx_cm dy_cm dz_cm tau_ms time_s "ground residuals used"
  for run in "${RUNS[@]}"; do
    seq=${run%%__*}
    set=${run#*__}
    dir=$WORK/runs/$run
    if [ ! -s "$dir/calibration.txtpb" ]; then
      printf '%-8s %-11s %s\n' "$seq" "$set" "FAILED: $(tail -1 "$dir/stderr.txt" 2>/dev/null)"
      continue
    fi
    used=$({ grep -E '^ground_residuals_used:' "$dir/calibration.txtpb" || true; } |
      sed -E 's/.*"(.*)"/\1/' | paste -sd+ -)
    read -r yaw tilt < <(rotation_split "$dir/calibration.txtpb" "$dir/truth.txtpb")
    awk -F, -v name="$run" -v seq="$seq" -v set="$set" -v secs="$(cat "$dir/seconds.txt")" \
      -v used="${used:-none}" -v yaw="$yaw" -v tilt="$tilt" '
      $1 == name { printf "%-8s %-11s %7.3f %7.3f %7.3f %8.2f %8.2f %8.2f %8.3f %6d  %s\n",
                   seq, set, $9, yaw, tilt, $10, $11, $12, $13, secs, used }' "$WORK/errors.csv"
  done
} | tee "$WORK/table.txt"
