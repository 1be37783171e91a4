#!/usr/bin/env bash
# Builds and runs every benchmark; the figures belong in docs/performance.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
for bench in build/bin/*_bench; do
  "$bench" "$@"
done
