#!/usr/bin/env bash
# Installs the Debian packages Follicle needs. Idempotent: skips apt when everything is present.
set -euo pipefail
PKGS=(
  cmake ninja-build pkg-config g++ clang-format
  libeigen3-dev libembree-dev libtbb-dev libstb-dev libjpeg-dev libtinyobjloader-dev libtinygltf-dev
  nlohmann-json3-dev libopenexr-dev libcli11-dev libfmt-dev libspdlog-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libegl-dev libopengl-dev libgl1-mesa-dri libglfw3-dev libimgui-dev libmeshoptimizer-dev
  xvfb xauth xdotool ffmpeg
  python3-dev pybind11-dev python3-numpy python3-pytest
  blender
)
missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PKGS[@]} packages present"
  exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
$SUDO apt-get -o DPkg::Lock::Timeout=600 update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
  -o DPkg::Lock::Timeout=600 "${missing[@]}"
