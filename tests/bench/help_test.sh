#!/usr/bin/env bash
# Every bench script (bench/**/*.sh but the sourced libraries) parses, uses
# the harness bench/common.sh and answers --help with exit 0 and the usage:
# its header comment and the harness's "Options" list.
#   tests/bench/help_test.sh
set -euo pipefail
SRC=$(cd "$(dirname "$0")/../.." && pwd)
# Sourced by the scripts, not run.
LIBRARIES=(bench/common.sh bench/calibrate/simulated_inputs.sh)
failures=0 count=0
fail() { echo "FAIL $1: $2"; failures=$((failures + 1)); }
while IFS= read -r script; do
  case " ${LIBRARIES[*]} " in *" $script "*) continue ;; esac
  count=$((count + 1))
  bash -n "$SRC/$script" 2> /dev/null || { fail "$script" "bash -n"; continue; }
  grep -q '^\. "$(dirname "$0")/\.\./common\.sh"' "$SRC/$script" ||
    { fail "$script" "does not source bench/common.sh"; continue; }
  status=0
  out=$(cd /tmp && timeout 20 bash "$SRC/$script" --help 2>&1) || status=$?
  [ $status -eq 0 ] || { fail "$script" "--help exited $status: $(echo "$out" | tail -1)"; continue; }
  grep -q '^Options (--flag VALUE or --flag=VALUE):$' <<< "$out" ||
    { fail "$script" "--help printed no harness Options list"; continue; }
  [ -n "$(sed -n '1p' <<< "$out")" ] || fail "$script" "--help printed no header comment"
done < <(cd "$SRC" && find bench -name '*.sh' | sort)
[ $count -gt 0 ] || { echo "FAIL: no bench scripts found"; exit 1; }
echo "$count bench scripts, $failures failing"
[ $failures -eq 0 ]
