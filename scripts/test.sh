#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite (ctest). --sanitize: the same under
# AddressSanitizer + UndefinedBehaviorSanitizer, less the tests labelled `accuracy` (whole
# recordings against the path tracer, which the plain pass runs; under the sanitizers they cost
# most of CI's time and reach no code the other tests do not) and `browser` (the viewer in
# Chromium: its JavaScript gains nothing from them; the server's C++ is tested under them by
# serve/lighting_server_test) and `batch` (the Snakemake workflow, Python and shell, locally and
# on Slurm; the daylit commands it runs are tested under them by cli_test). --loaded: the same beside a CPU hog on every core (stress-ng), as
# on a user's busy laptop: no test may need an idle machine (issue 41).
set -euo pipefail
cd "$(dirname "$0")/.."
loaded=0
args=()
for arg in "$@"; do
  if [ "$arg" = "--loaded" ]; then loaded=1; else args+=("$arg"); fi
done
set -- "${args[@]}"
build_dir=$(bash scripts/build.sh "$@" | tail -n 1)
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export MESA_SHADER_CACHE_DIR="${MESA_SHADER_CACHE_DIR:-$PWD/$build_dir/mesa-cache}"
filter=()
if [ "${1:-}" = "--sanitize" ]; then
  filter=(-LE 'accuracy|browser|batch')
  # The recordings' bakes that the plain pass made (build/test-cache) have the same cache key here
  # (the same files, options and bake code), so the fixture loads them instead of baking again
  # under the sanitizers; without them it bakes. The bake's code runs under the sanitizers in
  # bake/bake_test and cli_test's bake test.
  for cached in build/test-cache/*/; do
    [ -f "$cached/bake.json" ] || continue
    name=$(basename "$cached")
    if [ ! -f "$build_dir/test-cache/$name/bake.json" ]; then
      mkdir -p "$build_dir/test-cache"
      rm -rf "$build_dir/test-cache/$name"
      cp -r "$cached" "$build_dir/test-cache/$name"
    fi
  done
fi
cd "$build_dir"
if [ "$loaded" -eq 1 ]; then
  stress-ng --cpu "$(nproc)" --timeout 7200 >/dev/null 2>&1 &
  hog=$!
  trap 'kill "$hog" 2>/dev/null || true' EXIT
fi
ctest -j "$(nproc)" --output-on-failure --timeout 600 "${filter[@]}"
