# Helpers that give every target of the project the same warnings, sanitizers,
# linker and output directories. Sources are always listed explicitly.

# lld when the compiler can link with it (scripts/setup.sh installs it): the
# executables link in a fraction of GNU ld's time; the code is the same.
include(CheckLinkerFlag)
check_linker_flag(CXX -fuse-ld=lld TILTCAL_HAVE_LLD)

# tiltcal_set_target_options(TARGET [TEST]): TEST for a test executable (and
# its precompiled header), whose own code needs no fuzzing coverage.
function(tiltcal_set_target_options target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wno-unused-parameter)
  if(TILTCAL_UNITY_BUILD AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # In a batch a file is no longer the main file, and GCC then warns about
    # a class with external linkage holding a type of an anonymous namespace
    # (subobject-linkage), which the same file compiled alone does not.
    target_compile_options(${target} PRIVATE -Wno-subobject-linkage)
  endif()
  if(TILTCAL_HAVE_LLD)
    target_link_options(${target} PRIVATE -fuse-ld=lld)
  endif()
  if(TILTCAL_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(TILTCAL_SANITIZE)
    # "undefined" does not include float -> integer casts out of range; every
    # finding stops the program (a test or fuzz run fails, never scrolls by).
    set(sanitize ${TILTCAL_SANITIZE})
    if(sanitize MATCHES "undefined")
      string(APPEND sanitize ",float-cast-overflow")
    endif()
    target_compile_options(${target} PRIVATE -fsanitize=${sanitize} -fno-sanitize-recover=all
                                             -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=${sanitize})
  endif()
  if(TILTCAL_FUZZ AND NOT "TEST" IN_LIST ARGN)
    # Coverage for libFuzzer in every library and harness (the tests link the
    # same instrumented libraries); the harnesses add its main.
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
  if(CMAKE_BUILD_TYPE STREQUAL "Debug")
    target_compile_definitions(${target} PRIVATE EIGEN_INITIALIZE_MATRICES_BY_NAN)
  endif()
endfunction()

# Precompiled headers (TILTCAL_PCH): cmake/pch.h for the libraries,
# cmake/pch_test.h for the tests, each compiled once, by an empty object
# library with the same options, and reused by every target (REUSE_FROM).
# GCC uses a precompiled header only when it was made with the same options
# and macros, and otherwise reads the header as text: a target that cannot
# share one (tiltcal_registration, compiled with -fopenmp; the odometry,
# with PCL's -fPIC) goes without (NO_PCH); for its one or two files, making
# its own would cost more than it saves.
# Clang (the sanitizer build) stops with an error on such a mismatch instead,
# so a target whose options differ fails there loudly, never silently slower.
function(tiltcal_pch_enabled out)
  if(TILTCAL_PCH)
    set(${out} TRUE PARENT_SCOPE)
  else()
    set(${out} FALSE PARENT_SCOPE)
  endif()
endfunction()

# tiltcal_use_pch(TARGET LIBRARY|TEST)
function(tiltcal_use_pch target kind)
  tiltcal_pch_enabled(enabled)
  if(NOT enabled)
    return()
  endif()
  # A precompiled header that GCC cannot use is a warning (not an error
  # under TILTCAL_WERROR): the build is right, only slower.
  target_compile_options(${target} PRIVATE -Winvalid-pch -Wno-error=invalid-pch)
  set(owner tiltcal_pch)
  set(header ${PROJECT_SOURCE_DIR}/cmake/pch.h)
  set(deps tiltcal_proto Eigen3::Eigen fmt::fmt)
  if(kind STREQUAL "TEST")
    set(owner tiltcal_test_pch)
    set(header ${PROJECT_SOURCE_DIR}/cmake/pch_test.h)
    list(APPEND deps GTest::gtest)
  endif()
  if(NOT TARGET ${owner})
    add_library(${owner} OBJECT ${PROJECT_SOURCE_DIR}/cmake/pch_owner.cc)
    target_include_directories(${owner} PRIVATE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${owner} PRIVATE ${deps})
    tiltcal_set_target_options(${owner} ${kind})
    target_precompile_headers(${owner} PRIVATE ${header})
  endif()
  target_precompile_headers(${target} REUSE_FROM ${owner})
  # The owner's dependencies bring their definitions (fmt's FMT_SHARED, say):
  # without them a target that needs no fmt would not match the header.
  target_link_libraries(${target} PRIVATE ${deps})
endfunction()

# tiltcal_add_library(NAME SRCS ... DEPS ... [NO_PCH])
# A unity build with TILTCAL_UNITY_BUILD (default): the sources are compiled
# in batches of 8 as one file each, so the headers and templates they share
# are compiled once per batch. Names at file scope, anonymous namespaces
# included, must then differ between the files of one library.
# NO_PCH: no precompiled header (for options that change what the headers
# define or how they compile, as -fopenmp does, or PCL's -fPIC).
function(tiltcal_add_library)
  cmake_parse_arguments(ARG "NO_PCH" "NAME" "SRCS;DEPS" ${ARGN})
  add_library(${ARG_NAME} STATIC ${ARG_SRCS})
  set_target_properties(${ARG_NAME} PROPERTIES UNITY_BUILD ${TILTCAL_UNITY_BUILD})
  target_include_directories(${ARG_NAME} PUBLIC ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/generated)
  target_link_libraries(${ARG_NAME} PUBLIC ${ARG_DEPS})
  tiltcal_set_target_options(${ARG_NAME})
  if(NOT ARG_NO_PCH)
    tiltcal_use_pch(${ARG_NAME} LIBRARY)
  endif()
endfunction()

# tiltcal_add_stage(NAME decode SRCS lib sources... DEPS ...)
# Builds tiltcal_<NAME>_lib from SRCS and the executable tiltcal_<NAME> from
# main.cc of the current directory, landing in build/bin/. A stage with a
# default_params.txtpb gets it compiled in as tiltcal::<NAME>::DefaultParamsText()
# ("stages/<NAME>/default_params_text.h"), so that the file stays the one
# place where the defaults are written.
function(tiltcal_add_stage)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS" ${ARGN})
  set(defaults_file ${CMAKE_CURRENT_SOURCE_DIR}/default_params.txtpb)
  if(EXISTS ${defaults_file})
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${defaults_file})
    file(READ ${defaults_file} TILTCAL_DEFAULT_PARAMS)
    string(TOUPPER ${ARG_NAME} ARG_NAME_UPPER)
    set(generated ${PROJECT_BINARY_DIR}/generated/stages/${ARG_NAME})
    configure_file(${PROJECT_SOURCE_DIR}/cmake/default_params_text.h.in
                   ${generated}/default_params_text.h @ONLY)
    configure_file(${PROJECT_SOURCE_DIR}/cmake/default_params_text.cc.in
                   ${generated}/default_params_text.cc @ONLY)
    list(APPEND ARG_SRCS ${generated}/default_params_text.cc)
  endif()
  tiltcal_add_library(NAME tiltcal_${ARG_NAME}_lib SRCS ${ARG_SRCS} DEPS ${ARG_DEPS})
  add_executable(tiltcal_${ARG_NAME} main.cc)
  target_link_libraries(tiltcal_${ARG_NAME} PRIVATE tiltcal_${ARG_NAME}_lib)
  tiltcal_set_target_options(tiltcal_${ARG_NAME})
endfunction()

# tiltcal_add_test(NAME SRCS ... DEPS ... [LABELS ...] [COST SECONDS]
#                  [ONE_PROCESS_SUITES SUITE ...])
# One GoogleTest executable; every test case is registered with CTest. Tests
# find the shared fixtures and the project tree through compile definitions.
# The executable is a unity build (TILTCAL_UNITY_BUILD): its sources are
# compiled in batches as one file, so the headers and templates they share
# are compiled once per batch (about half the CPU time of compiling them one
# by one). Names at file scope, anonymous namespaces included, must then
# differ between the files of one executable.
# COST: about the seconds of its slowest test case. ctest -j starts the tests
# of highest cost first; a fresh build has no timings of an earlier run, and
# without it the long tests declared last would run alone at the end.
# ONE_PROCESS_SUITES: suites whose cases share what their SetUpTestSuite
# makes (a simulated sequence, say). Each is one CTest test, named after the
# suite, that runs its cases in one process, so that it is made once rather
# than once per case; COST is then about the seconds of the whole suite.
function(tiltcal_add_test)
  cmake_parse_arguments(ARG "" "NAME;COST" "SRCS;DEPS;LABELS;ONE_PROCESS_SUITES" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} tiltcal_testing GTest::gtest GTest::gtest_main)
  set_target_properties(${ARG_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests
                                               UNITY_BUILD ${TILTCAL_UNITY_BUILD})
  tiltcal_set_target_options(${ARG_NAME} TEST)
  tiltcal_use_pch(${ARG_NAME} TEST)
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  if(NOT ARG_COST)
    set(ARG_COST 0)
  endif()
  set(others "")
  foreach(suite IN LISTS ARG_ONE_PROCESS_SUITES)
    add_test(NAME ${suite} COMMAND ${ARG_NAME} --gtest_filter=${suite}.*
             WORKING_DIRECTORY ${PROJECT_BINARY_DIR})
    set_tests_properties(${suite} PROPERTIES LABELS "${ARG_LABELS}" COST ${ARG_COST})
    string(APPEND others "${suite}.*:")
  endforeach()
  if(others)
    set(others TEST_FILTER "-${others}")
  endif()
  gtest_discover_tests(${ARG_NAME}
    WORKING_DIRECTORY ${PROJECT_BINARY_DIR}
    ${others}
    PROPERTIES LABELS "${ARG_LABELS}" COST ${ARG_COST}
    DISCOVERY_TIMEOUT 60)
endfunction()
