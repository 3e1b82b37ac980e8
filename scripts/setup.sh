#!/usr/bin/env bash
# Installs the Debian 12 packages bounce needs when they are missing, then configures and
# builds with a CMake preset.  Usage: scripts/setup.sh [default|clang|sanitize]
# Runs as root (apt-get) or as a user with sudo; does nothing to packages already present.
set -euo pipefail
preset="${1:-default}"
cd "$(dirname "$0")/.."

# openimageio-tools: Debian's OpenImageIOTargets.cmake names /usr/bin/iconvert and friends, so
# find_package(OpenImageIO) fails without them (libopenimageio-dev does not depend on it).
packages=(
  build-essential cmake ninja-build pkg-config git
  libglm-dev libembree-dev libtbb-dev
  libegl-dev libgl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri libepoxy-dev
  catch2 libopenimageio-dev openimageio-tools libtinyobjloader-dev libcli11-dev nlohmann-json3-dev libfmt-dev
  libtinygltf-dev glslang-tools glslang-dev spirv-tools libvulkan-dev mesa-vulkan-drivers
  python3 python3-matplotlib
)
[ "$preset" = clang ] && packages+=(clang)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

cmake --preset "$preset"
cmake --build --preset "$preset" -j "$(nproc)"
