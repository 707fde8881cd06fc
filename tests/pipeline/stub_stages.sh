# Sourced by the Makefile.pipeline tests (bash): make_stub_stages BIN writes
# stand-ins for every stage binary (BIN/tiltcal_*) and for the interpreter of
# the plot scripts (BIN/python).
# A stub stage writes every --out*=PATH it is given; tiltcal_inspect also
# prints a CSV header. With STUB_LOG set it appends "NAME ARGS..." to that
# file, with STUB_SLEEP_S set it first sleeps that long (a stage that takes a
# moment). It fails when TILTCAL_STUB_FAIL names it (after writing, as a
# crash midway would), and exits 3 (result written, verdict SUSPECT) when
# TILTCAL_STUB_SUSPECT names it.
make_stub_stages() {
  local bin=$1 stage
  mkdir -p "$bin"
  cat > "$bin/stub" <<'STUB'
#!/usr/bin/env bash
name=$(basename "$0")
[ -n "${STUB_SLEEP_S:-}" ] && sleep "$STUB_SLEEP_S"
for arg in "$@"; do
  case "$arg" in --out*=*) echo "$name" > "${arg#*=}" ;; esac
done
[ "$name" = tiltcal_inspect ] && echo "stamp_ns,valid,normal_in_lidar.z,height_m"
[ -n "${STUB_LOG:-}" ] && echo "$name $*" >> "$STUB_LOG"
[ "${TILTCAL_STUB_FAIL:-}" = "$name" ] && exit 1
[ "${TILTCAL_STUB_SUSPECT:-}" = "$name" ] && exit 3
exit 0
STUB
  chmod +x "$bin/stub"
  for stage in decode initial_extrinsic ground gravity gravity_reference calibrate dataset_calibration report inspect; do
    ln -sf stub "$bin/tiltcal_$stage"
  done
  cat > "$bin/python" <<'STUB'
#!/usr/bin/env bash
for arg in "$@"; do
  case "$arg" in
    --out=*) echo png > "${arg#*=}" ;;
    --out_dir=*) echo png > "${arg#*=}/extrinsic_positions.png"; echo png > "${arg#*=}/extrinsic_spread.png" ;;
  esac
done
STUB
  chmod +x "$bin/python"
}
