#!/usr/bin/env bash
# Installs the Debian 12 packages the project builds, tests and runs with.
set -euo pipefail
PACKAGES=(build-essential cmake ninja-build pkg-config zlib1g-dev
  libvulkan-dev mesa-vulkan-drivers vulkan-tools glslang-tools
  libglm-dev libopenexr-dev libcpp-httplib-dev nlohmann-json3-dev
  libglfw3-dev libimgui-dev xvfb xauth xdotool
  libgtest-dev libgmock-dev libbenchmark-dev python3 python3-yaml
  clang-14 libclang-rt-14-dev clang-format curl jq
  # docs/dependencies.md says why each package is here.
  libcli11-dev libstb-dev libxxhash-dev libhwy-dev libembree-dev nginx)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y "${missing[@]}"
fi
