#!/usr/bin/env bash
# The main job on a recording (default: the bundled courtyard-a), headless. Sets up and builds
# first: only the packages and the one target (`daylit`) it needs (scripts/build.sh --main). Writes into OUT (default out/<recording name>/):
#   info.txt  what `daylit info` says of the recording (validation, frames, sun path, surfaces)
#   sun.csv   the sun for every frame (topocentric zenith/azimuth and the scene vector)
#   sun.png   the sun's elevation and azimuth over the recording
#   bake/     the offline scene maps (env-map and camera albedo, sky visibility, gather tables,
#             albedo.csv, PNG previews); re-used while the recording is unchanged
#   replay.mp4  the augmented video: every frame with the scene's virtual objects, lit by that
#             frame's estimate and shadowed both ways (daylit replay)
#   estimates.csv, bursts.csv, lighting.png
#             the sun and sky per frame, per burst (frames less than 2 s apart), and their plot
#   figures.json  the report's figures under stable keys (scripts/results.sh reads them)
#   report.txt  speed, and with ground truth the lighting's errors and the composite's fidelity
#   fidelity.csv, fidelity.png, worst_vs_truth.png
#             with ground truth: per truth frame, the composite against the path tracer's
set -euo pipefail
cd "$(dirname "$0")/.."
recording=${1:-recordings/courtyard-a}
bash scripts/build.sh --main >/dev/null
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
"$daylit" replay "$recording" --cache "$out/bake" --out "$out/replay.mp4"
echo "results in $out/"
