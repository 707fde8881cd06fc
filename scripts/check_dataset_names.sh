#!/usr/bin/env bash
# Names in a dataset folder that Makefile.pipeline would turn into sequences,
# bag files or truths and that hold a character outside the safe set
# (ASCII letters, digits and . _ - + @ /): one line per name on stderr,
# naming the file (shell-quoted when it holds a control character such as a
# newline) and the characters;
# the number of such names on stdout. Make reads names as words and pastes
# them into shell commands, so such a name is refused before anything runs.
#   scripts/check_dataset_names.sh DATASET OUT_FOLDER_NAME
# Entries checked, as the Makefile finds them (hidden names are not
# sequences): DATASET/*.bag, *.mcap, *.db3, *.truth.txtpb; every folder
# DATASET/*/ (but params/, the output folder and datasets, which hold a
# rig.txtpb) holding metadata.yaml or bag files, and those bag files.
set -uo pipefail
export LC_ALL=C
dataset=${1:?usage: check_dataset_names.sh DATASET OUT_FOLDER_NAME}
out_name=${2:-out}
unsafe=0

# The characters of $1 outside the safe set, each once, blanks and control
# characters spelled out (\n, \t, space, \xNN).
unsafe_characters() {
  local name=$1 shown="" c i
  for ((i = 0; i < ${#name}; i++)); do
    c=${name:i:1}
    [[ $c == [A-Za-z0-9._+@/-] ]] && continue
    case $c in
      ' ') c=space ;;
      $'\n') c='\n' ;;
      $'\t') c='\t' ;;
      [[:cntrl:]]) printf -v c '\\x%02x' "'$c" ;;
    esac
    [[ " $shown " == *" $c "* ]] || shown+="${shown:+ }$c"
  done
  printf '%s' "$shown"
}

check() {  # check PATH_RELATIVE_TO_DATASET
  local characters
  characters=$(unsafe_characters "$1")
  [ -z "$characters" ] && return
  local shown=$1
  [[ $shown == *[[:cntrl:]]* ]] && printf -v shown '%q' "$shown"
  printf '%s/%s: the name holds characters the pipeline cannot carry safely: %s\n' \
    "$dataset" "$shown" "$characters" >&2
  unsafe=$((unsafe + 1))
}

is_bag() { case $1 in *.bag | *.mcap | *.db3) return 0 ;; esac; return 1; }

if ! cd -- "$dataset" 2>/dev/null; then
  # No dataset folder: make says so when it looks for the rig.
  echo 0
  exit 0
fi
shopt -s nullglob
for entry in *; do
  if is_bag "$entry" || [[ $entry == *.truth.txtpb ]]; then
    check "$entry"
  elif [ -d "$entry" ] && [ "$entry" != params ] && [ "$entry" != "$out_name" ] &&
       [ ! -e "$entry/rig.txtpb" ]; then
    inner=()
    for file in "$entry"/*; do
      name=${file#"$entry"/}
      if is_bag "$name" || [ "$name" = metadata.yaml ]; then inner+=("$file"); fi
    done
    if [ ${#inner[@]} -gt 0 ]; then
      check "$entry"
      for file in "${inner[@]}"; do check "$file"; done
    fi
  fi
done
echo "$unsafe"
