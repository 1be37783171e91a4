#!/usr/bin/env bash
# Installs every Debian package daylit uses (build, tests, benchmarks, headless GL,
# video). Idempotent and quiet: when everything is already installed it only checks.
# Run as root (or with sudo available) on Debian bookworm.
set -euo pipefail

packages=(
  build-essential cmake pkgconf git
  libopencv-dev libavformat-dev libavcodec-dev libavutil-dev libswscale-dev libv4l-dev libgeographiclib-dev libceres-dev libeigen3-dev libunwind-dev
  libglm-dev libglfw3-dev libegl-dev libgl-dev libgles-dev libepoxy-dev libegl-mesa0
  libgl1-mesa-dri libgbm-dev libopenexr-dev libimath-dev libembree-dev libtbb-dev
  libgtest-dev libgmock-dev libbenchmark-dev nlohmann-json3-dev libcli11-dev
  libcpp-httplib-dev libspdlog-dev libfmt-dev libtinyobjloader-dev libtinygltf-dev libstb-dev liberfa-dev
  ffmpeg xvfb xauth clang libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q '^install ok installed$'; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
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
