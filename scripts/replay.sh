#!/usr/bin/env bash
# The main job on a recording (default: the bundled courtyard-a), headless. Sets up and builds
# first. Writes into OUT (default out/<recording name>/):
#   info.txt  what `daylit info` says of the recording (validation, frames, sun path, surfaces)
#   sun.csv   the sun for every frame (topocentric zenith/azimuth and the scene vector)
#   sun.png   the sun's elevation and azimuth over the recording
#   bake/     the offline scene maps (env-map and camera albedo, sky visibility, gather tables,
#             albedo.csv, PNG previews); re-used while the recording is unchanged
#   estimates.csv, lighting.png, lighting.txt
#             the sun and sky per frame, their plot, and (with ground truth) the median errors
# Later parts of the pipeline (relighting, rendering) join this job as they land.
set -euo pipefail
cd "$(dirname "$0")/.."
recording=${1:-recordings/courtyard-a}
bash scripts/build.sh >/dev/null
daylit=build/bin/daylit
name=$(basename "$(realpath "$recording")")
out=${2:-out/$name}
mkdir -p "$out"
"$daylit" info "$recording" | tee "$out/info.txt.tmp"
mv "$out/info.txt.tmp" "$out/info.txt"
"$daylit" sunpos --scene "$recording" --frames --out "$out/sun.csv" --plot "$out/sun.png"
"$daylit" bake "$recording" --cache "$out/bake" >/dev/null
echo "albedo per surface (from the env map):"
cat "$out/bake/albedo.csv"
"$daylit" estimate "$recording" --cache "$out/bake" --out "$out/estimates.csv" --plot "$out/lighting.png" \
  | tee "$out/lighting.txt.tmp"
mv "$out/lighting.txt.tmp" "$out/lighting.txt"
echo "results in $out/"
