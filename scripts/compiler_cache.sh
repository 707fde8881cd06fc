# Sourced by build.sh and sanitize_and_fuzz.sh: when ccache is installed,
# COMPILER_CACHE holds the cmake arguments that compile through it, and the
# sloppiness the precompiled headers need (pch_defines, time_macros; the
# header's file times) is set for it, whatever its configuration says.
# Without ccache COMPILER_CACHE is empty.
COMPILER_CACHE=()
if command -v ccache > /dev/null; then
  COMPILER_CACHE=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
fi
