# Small helpers so that each folder's CMakeLists.txt is a few declarative lines.

set(DAYLIT_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion)

function(daylit_apply_flags target)
  target_compile_options(${target} PRIVATE ${DAYLIT_WARNINGS})
  if(DAYLIT_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(DAYLIT_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined
                                             -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
  if(DAYLIT_FUZZ)
    # Coverage for libFuzzer in every daylit library; the targets link -fsanitize=fuzzer (fuzz/).
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link,address,undefined
                                             -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()

# daylit_add_library(NAME daylit_x SRCS a.h a.cc LINK_LIBS ...)
function(daylit_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;LINK_LIBS" ${ARGN})
  add_library(${ARG_NAME} STATIC ${ARG_SRCS})
  target_include_directories(${ARG_NAME} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${ARG_NAME} PUBLIC ${ARG_LINK_LIBS})
  daylit_apply_flags(${ARG_NAME})
endfunction()

# The environment every test runs in: home, XDG folders and TMPDIR inside the build tree, so no
# test reads or writes the user's home or /tmp. Test binaries set it in their main()
# (base/test_main.cc); the fixture tests that run `daylit` itself get it as a CTest property.
set(DAYLIT_TEST_HOME ${PROJECT_BINARY_DIR}/test-home)
set(DAYLIT_TEST_ENVIRONMENT
    HOME=${DAYLIT_TEST_HOME} XDG_CACHE_HOME=${DAYLIT_TEST_HOME}/cache XDG_CONFIG_HOME=${DAYLIT_TEST_HOME}/config
    XDG_DATA_HOME=${DAYLIT_TEST_HOME}/share TMPDIR=${PROJECT_BINARY_DIR}/test-tmp)

# daylit_add_test(NAME x_test SRCS x_test.cc LINK_LIBS ... [ENVIRONMENT VAR=value]
#                 [FIXTURES fixture] [LABELS label]): one GoogleTest binary whose tests are registered with
# ctest under "<folder>/<name>" so `ctest -R sunmodel/` runs one module. Its main()
# (base/test_main.cc) keeps HOME, the XDG folders and TMPDIR inside the build tree. FIXTURES: the
# CTest fixture its tests need (courtyard_bakes, the bundled recordings' bakes: tests/). LABELS:
# `accuracy` marks a binary whose tests measure whole recordings against the path tracer; the
# sanitizer pass of scripts/test.sh leaves those out (the same code runs there in smaller tests),
# and its build does not make them (DAYLIT_ACCURACY_TESTS=OFF).
function(daylit_add_test)
  if(NOT DAYLIT_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "NAME;ENVIRONMENT;FIXTURES;LABELS" "SRCS;LINK_LIBS" ${ARGN})
  if(ARG_LABELS STREQUAL "accuracy" AND NOT DAYLIT_ACCURACY_TESTS)
    return()
  endif()
  file(RELATIVE_PATH folder ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_LINK_LIBS} daylit_test_main)
  target_compile_definitions(${ARG_NAME} PRIVATE
    DAYLIT_SOURCE_DIR="${PROJECT_SOURCE_DIR}" DAYLIT_BINARY_DIR="${PROJECT_BINARY_DIR}")
  daylit_apply_flags(${ARG_NAME})
  set(properties)
  if(ARG_ENVIRONMENT)
    list(APPEND properties ENVIRONMENT "${ARG_ENVIRONMENT}")
  endif()
  if(ARG_FIXTURES)
    list(APPEND properties FIXTURES_REQUIRED "${ARG_FIXTURES}")
  endif()
  if(ARG_LABELS)
    list(APPEND properties LABELS "${ARG_LABELS}")
  endif()
  # (gtest_discover_tests flattens PROPERTIES: one value per property, no lists.)
  if(properties)
    set(properties PROPERTIES ${properties})
  endif()
  gtest_discover_tests(${ARG_NAME} TEST_PREFIX "${folder}/${ARG_NAME}." DISCOVERY_TIMEOUT 60
                       WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} ${properties})
endfunction()
