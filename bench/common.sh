# bench/common.sh: the harness every bench script sources.
#
#   . "$(dirname "$0")/../common.sh"       # sets REPO
#   bench_flag --seeds SEEDS "1 2 3" "simulator seeds"
#   bench_switch --clean CLEAN "delete the bags at the end"
#   bench_list --params PARAMS "calibrate params, repeatable"
#   bench_args "[CASE...]" "cases to run (default every case)"
#   bench_parse "$@"
#   require_binaries tiltcal_simulate tiltcal_decode
#
# bench_parse reads --flag VALUE and --flag=VALUE alike. Every script has
#   --build_dir DIR  the build whose bin/ runs (BUILD_DIR, BIN; default
#                    <repo>/build, or <repo>/$BENCH_BUILD_DIR when the script
#                    sets that before sourcing)
#   --scratch DIR    work folder (SCRATCH), kept; default a fresh folder under
#                    ${TMPDIR:-/tmp}, removed on exit unless --keep
#   --keep           keep the fresh scratch folder (its path is printed;
#                    BENCH_SCRATCH_REMOVED is 1 when it goes at exit)
#   --help           the script's header comment and the flags, exit 0
# Positional arguments land in BENCH_ARGS when the script called bench_args.
# Scripts add their own exit work with bench_on_exit 'COMMAND' (not trap).

REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BENCH_NAME=$(basename "$0")
BENCH_ARGS=()
BENCH_SCRATCH_REMOVED=0  # 1: SCRATCH is removed on exit
_bench_flags=()
_bench_args_usage=""
_bench_on_exit=""
declare -A _bench_var=() _bench_kind=() _bench_help=()

# bench_flag FLAG VAR DEFAULT HELP: --flag VALUE sets VAR (DEFAULT otherwise).
bench_flag() {
  _bench_flags+=("$1"); _bench_var[$1]=$2; _bench_kind[$1]=value
  _bench_help[$1]=$4${3:+ (default: $3)}
  printf -v "$2" '%s' "$3"
}
# bench_switch FLAG VAR HELP: --flag sets VAR to 1 (0 otherwise).
bench_switch() {
  _bench_flags+=("$1"); _bench_var[$1]=$2; _bench_kind[$1]=switch; _bench_help[$1]=$3
  printf -v "$2" '%s' 0
}
# bench_list FLAG VAR HELP: each --flag VALUE appends to the array VAR.
bench_list() {
  _bench_flags+=("$1"); _bench_var[$1]=$2; _bench_kind[$1]=list; _bench_help[$1]=$3
  eval "$2=()"
}
# bench_args USAGE HELP: the script takes positional arguments (BENCH_ARGS).
bench_args() { _bench_args_usage="$1  $2"; }
bench_on_exit() { _bench_on_exit+="$1"$'\n'; }

bench_flag --build_dir BUILD_DIR "$REPO/${BENCH_BUILD_DIR:-build}" "the build whose bin/ runs"
bench_flag --scratch SCRATCH "" "work folder, kept (default: a fresh one, removed on exit)"
bench_switch --keep KEEP "keep the fresh scratch folder"

# _bench_option NAME HELP: one option of the usage, HELP wrapped at 80 columns.
_bench_option() {
  printf '  %s\n' "$1"
  printf '%s\n' "$2" | fold -s -w 70 | sed -e 's/ *$//' -e 's/^/          /'
}

bench_usage() {
  # The header: the comment lines after the shebang, up to the first other line.
  sed -n '2,${/^#/!q;s/^# \{0,1\}//;p}' "$0"
  echo
  echo "Options (--flag VALUE or --flag=VALUE):"
  local f
  for f in "${_bench_flags[@]}"; do
    case ${_bench_kind[$f]} in
      value) _bench_option "$f ${_bench_var[$f]}" "${_bench_help[$f]}" ;;
      list) _bench_option "$f ${_bench_var[$f]}" "${_bench_help[$f]} (repeatable)" ;;
      switch) _bench_option "$f" "${_bench_help[$f]}" ;;
    esac
  done
  _bench_option --help "this text"
  [ -z "$_bench_args_usage" ] || _bench_option "${_bench_args_usage%%  *}" "${_bench_args_usage#*  }"
}

bench_die() { echo "$BENCH_NAME: $*" >&2; exit 2; }

bench_parse() {
  local arg flag value
  while [ $# -gt 0 ]; do
    arg=$1; shift
    case $arg in
      -h|--help) bench_usage; exit 0 ;;
      --) BENCH_ARGS+=("$@"); break ;;
      --*=*) flag=${arg%%=*}; value=${arg#*=} ;;
      --*) flag=$arg; value="" ;;
      *) BENCH_ARGS+=("$arg"); continue ;;
    esac
    [ -n "${_bench_kind[$flag]:-}" ] || bench_die "unknown flag $flag (see --help)"
    if [ "${_bench_kind[$flag]}" = switch ]; then
      [ "$arg" = "$flag" ] || bench_die "$flag takes no value"
      printf -v "${_bench_var[$flag]}" '%s' 1
      continue
    fi
    if [ "$arg" = "$flag" ]; then
      [ $# -gt 0 ] || bench_die "$flag needs a value"
      value=$1; shift
    fi
    if [ "${_bench_kind[$flag]}" = list ]; then
      eval "${_bench_var[$flag]}+=(\"\$value\")"
    else
      printf -v "${_bench_var[$flag]}" '%s' "$value"
    fi
  done
  [ ${#BENCH_ARGS[@]} -eq 0 ] || [ -n "$_bench_args_usage" ] ||
    bench_die "unexpected argument ${BENCH_ARGS[0]} (see --help)"
  case $BUILD_DIR in /*) ;; *) BUILD_DIR=$PWD/$BUILD_DIR ;; esac
  BIN=$BUILD_DIR/bin
  if [ -z "$SCRATCH" ]; then
    SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/tiltcal_${BENCH_NAME%.sh}.XXXXXX")
    if [ "$KEEP" = 1 ]; then
      echo "$BENCH_NAME: scratch kept in $SCRATCH" >&2
    else
      _bench_on_exit+="rm -rf -- $(printf %q "$SCRATCH")"$'\n'
      BENCH_SCRATCH_REMOVED=1
    fi
  else
    mkdir -p "$SCRATCH"
    SCRATCH=$(cd "$SCRATCH" && pwd)
  fi
  trap 'eval "$_bench_on_exit"' EXIT
}

# require_binaries NAME...: each NAME executable in $BIN, or one line naming
# the first missing one and how to build it, and exit 2.
require_binaries() {
  local b
  for b in "$@"; do
    [ -x "$BIN/$b" ] || bench_die "$BIN/$b missing; build it: cmake --build $BUILD_DIR --target $b (a new build: BUILD_DIR=$BUILD_DIR scripts/build.sh)"
  done
}
