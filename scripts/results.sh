#!/usr/bin/env bash
# Measures every figure of docs/results.md and writes the page again from docs/results.md.in:
#   - every Google Benchmark target in bench/ (median of 3 repetitions),
#   - the recording tests, whose figures gtest writes as JSON (tests/courtyard_fixture.h's
#     RecordFigure),
#   - daylit estimate and daylit replay of each bundled recording (their figures.json),
#   - daylit lights on the bundled probes (seed 002's benchmark: errors.csv, automatic.json),
#   - the machine (cores, CPU, memory, compiler; the GL renderer from the replay).
# The raw JSON stays in build/results/. Run on an idle machine: about 25 minutes on 2 cores.
# `daylit results` refuses to write the page if any field of the template was not measured.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
daylit=build/bin/daylit
out=build/results
rm -rf "$out"
mkdir -p "$out/bench" "$out/tests"
export MESA_SHADER_CACHE_DIR="$PWD/build/mesa-cache"

json_text() { sed 's/\\/\\\\/g; s/"/\\"/g' <<<"$1"; }
{
  printf '{\n'
  printf '  "cores": %s,\n' "$(nproc)"
  printf '  "cpu": "%s",\n' "$(json_text "$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)")"
  printf '  "memory_gib": %s,\n' "$(awk '/^MemTotal/ { printf "%.0f", $2 / 1048576 }' /proc/meminfo)"
  printf '  "os": "%s",\n' "$(json_text "$(. /etc/os-release && echo "$PRETTY_NAME")")"
  printf '  "compiler": "%s"\n' "$(json_text "$(c++ --version | head -n 1)")"
  printf '}\n'
} >"$out/machine.json"

for bench in build/bin/*_bench; do
  name=$(basename "$bench")
  echo "results: $name" >&2
  "$bench" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
    --benchmark_out="$out/bench/$name.json" --benchmark_out_format=json >/dev/null
done

for test in build/tests/*_recording_test; do
  name=$(basename "$test")
  echo "results: $name" >&2
  "$test" --gtest_output="json:$out/tests/$name.json" >/dev/null
done

for recording in recordings/*/; do
  name=$(basename "$recording")
  echo "results: daylit estimate and replay of $name" >&2
  mkdir -p "$out/$name/replay"
  "$daylit" -q estimate "$recording" --cache "build/results-cache/$name" --out "$out/$name/estimates.csv" \
    --figures "$out/$name/estimate.json" --residuals "$out/$name/residuals" >/dev/null
  # The end-to-end rate on a shared 2-core virtual machine moves by ±15% from run to run: five runs
  # more, for their median and their slowest.
  mkdir -p "$out/$name/runs"
  for run in 1 2 3 4 5; do
    "$daylit" -q estimate "$recording" --cache "build/results-cache/$name" --out "$out/$name/runs/estimates.csv" \
      --figures "$out/$name/runs/$run.json" >/dev/null
  done
  fps=$(sed -n 's/^ *"fps": *\([0-9.e+-]*\),*$/\1/p' "$out/$name"/runs/*.json | sort -g)
  printf '{\n  "runs": 5,\n  "median_fps": %s,\n  "slowest_fps": %s\n}\n' "$(sed -n 3p <<<"$fps")" "$(head -n 1 <<<"$fps")" \
    >"$out/$name/estimate_runs.json"
  "$daylit" -q replay "$recording" --cache "build/results-cache/$name" --out "$out/$name/replay/replay.mp4" >/dev/null
  # The scene's calibration from its footage (docs/calibrate.md), the bake cached: north and clock,
  # then with the camera's rotation.
  mkdir -p "$out/$name/calibrated"
  "$daylit" -q calibrate-scene "$recording" --cache "build/results-cache/$name" --out "$out/$name/calibrated/scene.json" \
    --figures "$out/$name/calibrate.json" >/dev/null
  "$daylit" -q calibrate-scene "$recording" --cache "build/results-cache/$name" --out "$out/$name/calibrated/scene.json" \
    --what north,clock,pose --figures "$out/$name/calibrate_pose.json" >/dev/null
done

# daylit live on the userspace V4L2 test device (tests/fakecam, docs/capture.md) serving
# courtyard-a's frames as YUYV at 30 fps: does the pipeline keep up with the camera?
echo "results: daylit live on the test device at 30 fps" >&2
live="$out/live"
mkdir -p "$live"
cp recordings/courtyard-a/model.obj recordings/courtyard-a/envmap.exr "$live/"
sed -z 's|"frames": {[^}]*}|"frames": {"device": "/dev/video-daylit-results", "fps": 30}|; s|,[[:space:]]*"groundtruth": {[^}]*}||' \
  recordings/courtyard-a/scene.json >"$live/scene.json"
# The clock (libfaketime) at the recording's own time of day, so that the sun its frames show is up
# and moves as they were recorded.
LD_PRELOAD="$PWD/build/tests/libdaylit_fakecam.so /usr/lib/x86_64-linux-gnu/faketime/libfaketimeMT.so.1" \
  FAKETIME="@2026-06-21 05:00:00" DAYLIT_FAKECAM_DEVICE=/dev/video-daylit-results \
  DAYLIT_FAKECAM_VIDEO=recordings/courtyard-a/video.mp4 DAYLIT_FAKECAM_FRAMES=60 DAYLIT_FAKECAM_FORMATS=YUYV \
  "$daylit" -q live --scene "$live/scene.json" --cache "build/results-cache/live" --frames 600 \
  --out "$live/live.mp4" >/dev/null

# Seed 002's benchmark on the five lat-long probes (docs/relight.md).
for probe in galileo_latlong_1024x512 stpeters_latlong_1024x512 uffizi-large_1024x512 rooitou_park_1k potsdamer_platz_1k; do
  echo "results: daylit lights on $probe" >&2
  "$daylit" -q lights "probes/$probe.hdr" --n 1-6,8,16,32,64,128 --threshold 0.05 --out "$out/lights/$probe" >/dev/null
done

"$daylit" results docs/results.md.in "$out" --out docs/results.md
