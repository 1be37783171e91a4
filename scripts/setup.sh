#!/usr/bin/env bash
# Installs every Debian package daylit uses (build, tests, benchmarks, headless GL,
# video, Chromium for the browser viewer's test), then the viewer's npm packages (three.js and
# the test's playwright-core and pngjs, pinned in web/package-lock.json) into web/node_modules.
#   scripts/setup.sh          everything (scripts/test.sh)
#   scripts/setup.sh --main   only what building and running the `daylit` command needs (the
#                             main job, scripts/replay.sh): no test, benchmark, sanitizer or
#                             browser packages, no npm
# Idempotent and quiet: when everything is already installed it only checks.
# Run as root (or with sudo available) on Debian bookworm.
set -euo pipefail

main_only=0
if [ "${1:-}" = "--main" ]; then main_only=1; fi

# Building and running `daylit` (headless GL through Mesa's EGL, video through libavcodec).
packages=(
  build-essential cmake pkgconf
  libopencv-dev libavformat-dev libavcodec-dev libavutil-dev libswscale-dev libv4l-dev libgeographiclib-dev libceres-dev libeigen3-dev libunwind-dev
  libglm-dev libglfw3-dev libegl-dev libgl-dev libgles-dev libepoxy-dev libegl-mesa0
  libgl1-mesa-dri libgbm-dev libopenexr-dev libimath-dev libembree-dev libtbb-dev
  nlohmann-json3-dev libcli11-dev
  libevent-dev libcpp-httplib-dev libspdlog-dev libfmt-dev libtinyobjloader-dev libtinygltf-dev libstb-dev liberfa-dev
)
# The tests, benchmarks, sanitizer and fuzz builds, the window tests' X server, the viewer's
# browser test, the live tests' faked clock, the loaded run's CPU hog, the batch workflow's engine
# (Snakemake, with matplotlib for its plot) and the single-node Slurm its test starts.
if [ "$main_only" -eq 0 ]; then
  packages+=(git libgtest-dev libgmock-dev libbenchmark-dev ffmpeg xvfb xauth clang libclang-rt-14-dev chromium faketime stress-ng
    snakemake python3-matplotlib slurm-wlm munge)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q '^install ok installed$'; then
    missing+=("$p")
  fi
done
# Node.js ≥ 20 runs the npm registry's packages (playwright-core needs it); Debian's own is 18,
# so it is only installed where there is none, and checked below.
if [ "$main_only" -eq 0 ] && { ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; }; then
  missing+=(nodejs npm)
fi

# The viewer's packages, exactly as web/package-lock.json pins them, once per change of it.
install_web() {
  local web stamp
  web="$(cd "$(dirname "$0")/.." && pwd)/web"
  stamp="$web/node_modules/.daylit-lock-sha256"
  local want
  want=$(sha256sum "$web/package-lock.json" | cut -d' ' -f1)
  if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then return 0; fi
  local major
  major=$(node -p 'process.versions.node.split(".")[0]' 2>/dev/null || echo 0)
  if [ "$major" -lt 20 ]; then
    echo "setup: Node.js $(node --version 2>/dev/null || echo none) is too old for the viewer's test (playwright-core needs 20 or later)" >&2
    exit 1
  fi
  echo "setup: installing the viewer's npm packages (web/package-lock.json)..." >&2
  local log
  log=$(mktemp /tmp/daylit-npm.XXXXXX.log)
  if ! (cd "$web" && npm ci --no-audit --no-fund) >"$log" 2>&1; then
    tail -n 30 "$log" >&2
    echo "setup: npm ci failed in $web; full log in $log" >&2
    exit 1
  fi
  rm -f "$log"
  echo "$want" >"$stamp"
}

if [ ${#missing[@]} -eq 0 ]; then
  if [ "$main_only" -eq 0 ]; then install_web; fi
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then sudo_cmd=(sudo); else
    echo "setup: ${#missing[@]} packages missing (${missing[*]}); run this script as root" >&2
    exit 1
  fi
fi

echo "setup: installing ${#missing[@]} Debian packages (once)..." >&2
log=$(mktemp /tmp/daylit-setup.XXXXXX.log)
if ! { "${sudo_cmd[@]}" apt-get update -q &&
       "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q \
         --no-install-recommends "${missing[@]}"; } >"$log" 2>&1; then
  tail -n 30 "$log" >&2
  echo "setup: apt-get failed; full log in $log" >&2
  exit 1
fi
rm -f "$log"
echo "setup: done" >&2
if [ "$main_only" -eq 0 ]; then install_web; fi
