#!/usr/bin/env bash
# Installs what daylit needs (scripts/setup.sh) and builds it.
#   scripts/build.sh              Release build in build/ (warnings are errors): everything
#   scripts/build.sh --main       the same build/, the `daylit` command alone (the main job,
#                                 scripts/replay.sh): only its packages, no tests or benchmarks
#   scripts/build.sh --sanitize   AddressSanitizer + UBSan build in build-asan/ (without the
#                                 benchmarks and the accuracy tests, which its pass does not run)
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=build
cmake_args=(-DCMAKE_BUILD_TYPE=Release -DDAYLIT_WERROR=ON -DDAYLIT_BUILD_TESTS=ON -DDAYLIT_BUILD_BENCH=ON
            -DDAYLIT_ACCURACY_TESTS=ON)
setup_args=()
targets=()
if [ "${1:-}" = "--main" ]; then
  # The tests and benchmarks stay as they were configured: a later scripts/build.sh turns them on.
  cmake_args=(-DCMAKE_BUILD_TYPE=Release -DDAYLIT_WERROR=ON)
  if [ ! -f build/CMakeCache.txt ]; then cmake_args+=(-DDAYLIT_BUILD_TESTS=OFF -DDAYLIT_BUILD_BENCH=OFF); fi
  setup_args=(--main)
  targets=(--target daylit)
elif [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-asan
  # clang, as the fuzz targets are built (scripts/fuzz.sh); -O1 -g1: line tables for the
  # sanitizers' stack traces, without full debug info (a third of the build's time on this
  # template-heavy code).
  export CC=clang CXX=clang++
  cmake_args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DDAYLIT_WERROR=ON -DDAYLIT_SANITIZE=ON
              -DDAYLIT_BUILD_BENCH=OFF -DDAYLIT_ACCURACY_TESTS=OFF "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
              "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG")
fi

bash scripts/setup.sh "${setup_args[@]}"
log=$(mktemp /tmp/daylit-configure.XXXXXX.log)
if ! cmake -S . -B "$build_dir" "${cmake_args[@]}" >"$log" 2>&1; then
  cat "$log" >&2
  exit 1
fi
rm -f "$log"
cmake --build "$build_dir" -j "$(nproc)" "${targets[@]}" -- --no-print-directory
echo "$build_dir"
