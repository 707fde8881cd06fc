# Sourced by the build and test scripts: phase_done NAME prints to stderr the
# wall time since the previous phase_done (or since sourcing), the CPU time
# (user + system) of the commands the script ran in that time, and the
# 1-minute load average, e.g. "phase: ctest 312.4 s, CPU 590.2 s (load 2.10)".
# CI's log then shows where its time goes; the CPU time varies less with the
# load of a shared machine than the wall time.
_phase_clk_tck=$(getconf CLK_TCK)
_phase_cpu_ticks() {
  # Fields 16 and 17 of /proc/PID/stat: CPU of the waited-for children.
  local f
  read -ra f < /proc/$$/stat
  echo $(( f[15] + f[16] ))
}
_phase_start=${EPOCHREALTIME/./}
_phase_cpu_start=$(_phase_cpu_ticks)
phase_done() {
  local now=${EPOCHREALTIME/./} cpu
  cpu=$(_phase_cpu_ticks)
  local ms=$(( (now - _phase_start) / 1000 ))
  local cpu_ds=$(( (cpu - _phase_cpu_start) * 10 / _phase_clk_tck ))
  printf 'phase: %s %d.%d s, CPU %d.%d s (load %s)\n' "$1" $((ms / 1000)) $((ms % 1000 / 100)) \
    $((cpu_ds / 10)) $((cpu_ds % 10)) "$(cut -d' ' -f1 /proc/loadavg)" >&2
  _phase_start=$now
  _phase_cpu_start=$cpu
}
