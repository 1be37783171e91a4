#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/targets.h: scene.json, OBJ, CSV, OpenEXR, Radiance HDR,
# glTF, the bake cache, a recording's video, the lighting server's request heads) with clang,
# -fsanitize=fuzzer,address,undefined, in build-fuzz/, and
# runs each for SECONDS (default 60; libFuzzer's -max_total_time), as many at once as there are
# cores. Seeds: each target's own small files plus the bundled recordings' scene.json, model.obj
# and CSV files; the corpus each run grows is kept in build-fuzz/corpus/ for the next run.
# Prints libFuzzer's summary line per target; exits 1 if any target crashed, leaked, hung or ran
# out of memory, naming the input it kept (build-fuzz/crashes/TARGET/). Keep such an input as a
# regression in fuzz/regressions/TARGET/ once it is fixed.
#   scripts/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then targets=(scene_json obj csv exr hdr gltf bake_cache video http_request); fi

bash scripts/setup.sh
build=build-fuzz
log=$(mktemp /tmp/daylit-fuzz-configure.XXXXXX.log)
if ! CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDAYLIT_FUZZ=ON \
       -DDAYLIT_BUILD_TESTS=OFF -DDAYLIT_BUILD_BENCH=OFF "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" \
       "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1" >"$log" 2>&1; then
  cat "$log" >&2
  exit 1
fi
rm -f "$log"
cmake --build "$build" -j "$(nproc)" --target fuzz_targets -- --no-print-directory >/dev/null

# The bundled files each target reads as its kind of input.
bundled() {
  case "$1" in
    scene_json) ls recordings/*/scene.json ;;
    obj) ls recordings/*/model.obj ;;
    csv) ls recordings/*/frames.csv recordings/*/groundtruth.csv ;;
    *) ;;
  esac
}

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:symbolize=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Everything a target writes stays inside the build tree.
export TMPDIR="$PWD/$build/tmp"
mkdir -p "$TMPDIR"

run_one() {
  local name=$1 seconds=$2 build=$3
  local bin="$build/fuzz/fuzz_$name" seeds="$build/seeds/$name" corpus="$build/corpus/$name"
  local crashes="$build/crashes/$name" out="$build/logs/$name.log"
  rm -rf "$seeds"
  mkdir -p "$seeds" "$corpus" "$crashes" "$build/logs"
  while read -r f; do [ -n "$f" ] && cp "$f" "$seeds/$(echo "$f" | tr / _)"; done < <(bundled "$name")
  # The target's own seeds: written by its initialisation, then read once.
  if ! DAYLIT_FUZZ_SEEDS="$seeds" "$bin" -runs=0 "$seeds" >"$out" 2>&1; then
    echo "fuzz_$name: a seed input fails; see $out" >&2
    return 1
  fi
  if "$bin" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=4096 -max_len=65536 \
       -artifact_prefix="$crashes/" -print_final_stats=0 "$corpus" "$seeds" >>"$out" 2>&1; then
    echo "fuzz_$name: $(grep -E '^Done [0-9]+ runs' "$out" | tail -n 1) (corpus $(ls "$corpus" | wc -l) inputs)"
  else
    echo "fuzz_$name: FAILED: $(grep -E 'ERROR: |==ERROR|runtime error|Assertion|deadly signal|not an InputError' "$out" | head -n 1)" >&2
    echo "fuzz_$name: kept $(ls -t "$crashes" | head -n 1 | sed "s|^|$crashes/|"); log $out" >&2
    return 1
  fi
}
export -f run_one bundled

status=0
printf '%s\n' "${targets[@]}" |
  xargs -P "$(nproc)" -I{} bash -c 'run_one "$@"' _ {} "$seconds" "$build" || status=1
exit $status
