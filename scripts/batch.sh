#!/usr/bin/env bash
# daylit over a folder of recordings with Snakemake (batch/Snakefile; docs/batch.md):
# info -> bake -> estimate -> replay for each recording, then OUT/results.csv (per recording),
# OUT/bursts.csv (per burst) and OUT/summary.png.
#
#   scripts/batch.sh RECORDINGS OUT [--slurm] [--cores N] [--jobs N] [--frames N] [--no-replay]
#                    [--cache DIR] [--daylit PATH] [-- SNAKEMAKE ARGS...]
#
# Locally it runs on --cores (default: all); with --slurm every step is a Slurm job (Snakemake's
# own Slurm executor; --jobs at once, default 100) with the cores, memory and time its rule
# states. It goes on past a failed recording (--keep-going) and a second run redoes only what did
# not finish. --cache: the bakes' root (default OUT/bake), one folder per recording; a current
# bake there is loaded, not made again. daylit is build/bin/daylit when built here, else the one on PATH.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
usage() { sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
[ $# -ge 2 ] || usage
recordings=$1 out=$2
shift 2
slurm=0 cores=all jobs=100 frames="" replay=true daylit="" cache=""
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --slurm) slurm=1 ;;
    --cores) cores=${2:?--cores needs a number}; shift ;;
    --jobs) jobs=${2:?--jobs needs a number}; shift ;;
    --frames) frames=${2:?--frames needs a number}; shift ;;
    --no-replay) replay=false ;;
    --daylit) daylit=${2:?--daylit needs a path}; shift ;;
    --cache) cache=${2:?--cache needs a folder}; shift ;;
    --) shift; extra=("$@"); break ;;
    *) echo "batch: unknown option $1" >&2; usage ;;
  esac
  shift
done
if [ ! -d "$recordings" ]; then
  echo "batch: $recordings: no such folder" >&2
  exit 2
fi
if ! compgen -G "$recordings/*/scene.json" >/dev/null; then
  echo "batch: $recordings holds no recording (a folder with a scene.json)" >&2
  exit 2
fi
if ! command -v snakemake >/dev/null 2>&1; then
  echo "batch: snakemake is not installed (Debian: apt-get install snakemake python3-matplotlib; scripts/setup.sh does)" >&2
  exit 1
fi
if [ -z "$daylit" ]; then
  if [ -x "$root/build/bin/daylit" ]; then daylit="$root/build/bin/daylit"; else daylit=$(command -v daylit || true); fi
fi
if [ -z "$daylit" ] || [ ! -x "$daylit" ]; then
  echo "batch: no daylit binary (build it: scripts/build.sh --main, or give --daylit PATH)" >&2
  exit 1
fi
mkdir -p "$out"
recordings=$(cd "$recordings" && pwd)
out=$(cd "$out" && pwd)
daylit=$(cd "$(dirname "$daylit")" && pwd)/$(basename "$daylit")

config=(recordings="$recordings" out="$out" daylit="$daylit" replay="$replay")
[ -n "$frames" ] && config+=(frames="$frames")
if [ -n "$cache" ]; then mkdir -p "$cache"; config+=(cache="$(cd "$cache" && pwd)"); fi
engine=(--cores "$cores")
if [ "$slurm" -eq 1 ]; then
  # One clear line where there is no cluster to talk to, instead of a failed submission per job.
  if ! command -v sbatch >/dev/null 2>&1; then
    echo "batch: --slurm: Slurm's commands are not installed (Debian: slurm-client)" >&2
    exit 1
  fi
  if ! why=$(sinfo --noheader --format=%P 2>&1 >/dev/null); then
    echo "batch: --slurm: the Slurm cluster is not reachable: $(printf '%s' "$why" | head -n 1)" >&2
    exit 1
  fi
  # Snakemake's executor reads $USER to guess an account; a job shell may lack it.
  export USER="${USER:-$(id -un)}"
  engine=(--slurm --jobs "$jobs")
fi
# The workflow's bookkeeping (.snakemake/, Slurm's job logs) lives in OUT.
exec snakemake --snakefile "$root/batch/Snakefile" --directory "$out" "${engine[@]}" --keep-going \
  --rerun-incomplete --printshellcmds --config "${config[@]}" "${extra[@]}"
