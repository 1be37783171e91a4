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
endfunction()

# daylit_add_library(NAME daylit_x SRCS a.h a.cc LINK_LIBS ...)
function(daylit_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;LINK_LIBS" ${ARGN})
  add_library(${ARG_NAME} STATIC ${ARG_SRCS})
  target_include_directories(${ARG_NAME} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${ARG_NAME} PUBLIC ${ARG_LINK_LIBS})
  daylit_apply_flags(${ARG_NAME})
endfunction()

# daylit_add_test(NAME x_test SRCS x_test.cc LINK_LIBS ... [ENVIRONMENT VAR=value ...]): one
# GoogleTest binary whose tests are registered with ctest under "<folder>/<name>" so
# `ctest -R sunmodel/` runs one module.
function(daylit_add_test)
  if(NOT DAYLIT_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "NAME" "SRCS;LINK_LIBS;ENVIRONMENT" ${ARGN})
  file(RELATIVE_PATH folder ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_LINK_LIBS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${ARG_NAME} PRIVATE
    DAYLIT_SOURCE_DIR="${PROJECT_SOURCE_DIR}" DAYLIT_BINARY_DIR="${PROJECT_BINARY_DIR}")
  daylit_apply_flags(${ARG_NAME})
  gtest_discover_tests(${ARG_NAME} TEST_PREFIX "${folder}/${ARG_NAME}." DISCOVERY_TIMEOUT 60
                       WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                       PROPERTIES ENVIRONMENT "${ARG_ENVIRONMENT}")
endfunction()
