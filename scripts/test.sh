#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite (ctest). --sanitize: the same under
# AddressSanitizer + UndefinedBehaviorSanitizer, less the tests labelled `accuracy` (whole
# recordings against the path tracer, which the plain pass runs; under the sanitizers they cost
# most of CI's time and reach no code the other tests do not) and `browser` (the viewer in
# Chromium: its JavaScript gains nothing from them; the server's C++ is tested under them by
# serve/lighting_server_test).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=$(bash scripts/build.sh "$@" | tail -n 1)
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export MESA_SHADER_CACHE_DIR="${MESA_SHADER_CACHE_DIR:-$PWD/$build_dir/mesa-cache}"
cd "$build_dir"
filter=()
if [ "${1:-}" = "--sanitize" ]; then filter=(-LE 'accuracy|browser'); fi
ctest -j "$(nproc)" --output-on-failure --timeout 600 "${filter[@]}"
