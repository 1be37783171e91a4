#!/usr/bin/env bash
# Builds and runs every benchmark (arguments go to each, e.g. --benchmark_filter=BM_Estimate);
# scripts/results.sh measures them all for docs/results.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
for bench in build/bin/*_bench; do
  "$bench" "$@"
done
