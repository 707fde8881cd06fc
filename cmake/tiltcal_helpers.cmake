# Helpers that give every target of the project the same warnings, sanitizers
# and output directories. Sources are always listed explicitly.

function(tiltcal_set_target_options target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wno-unused-parameter)
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
  if(TILTCAL_FUZZ)
    # Coverage for libFuzzer in every target; the harnesses add its main.
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
  if(CMAKE_BUILD_TYPE STREQUAL "Debug")
    target_compile_definitions(${target} PRIVATE EIGEN_INITIALIZE_MATRICES_BY_NAN)
  endif()
endfunction()

# tiltcal_add_library(NAME SRCS ... DEPS ...)
function(tiltcal_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS" ${ARGN})
  add_library(${ARG_NAME} STATIC ${ARG_SRCS})
  target_include_directories(${ARG_NAME} PUBLIC ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/generated)
  target_link_libraries(${ARG_NAME} PUBLIC ${ARG_DEPS})
  tiltcal_set_target_options(${ARG_NAME})
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

# tiltcal_add_test(NAME SRCS ... DEPS ... [LABELS ...] [COST SECONDS])
# One GoogleTest executable; every test case is registered with CTest. Tests
# find the shared fixtures and the project tree through compile definitions.
# COST: about the seconds of its slowest test case. ctest -j starts the tests
# of highest cost first; a fresh build has no timings of an earlier run, and
# without it the long tests declared last would run alone at the end.
function(tiltcal_add_test)
  cmake_parse_arguments(ARG "" "NAME;COST" "SRCS;DEPS;LABELS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} tiltcal_testing GTest::gtest GTest::gtest_main)
  set_target_properties(${ARG_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  tiltcal_set_target_options(${ARG_NAME})
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  if(NOT ARG_COST)
    set(ARG_COST 0)
  endif()
  gtest_discover_tests(${ARG_NAME}
    WORKING_DIRECTORY ${PROJECT_BINARY_DIR}
    PROPERTIES LABELS "${ARG_LABELS}" COST ${ARG_COST}
    DISCOVERY_TIMEOUT 60)
endfunction()
