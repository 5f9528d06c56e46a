#!/usr/bin/env bash
# Installs every Debian 12 package GDPT needs (compilers aside). Idempotent:
# runs `apt-get update` and `apt-get install` only when something is missing.
set -euo pipefail

PACKAGES=(
  cmake make g++ pkg-config clang-format
  clang libclang-rt-14-dev llvm
  libembree-dev libtbb-dev
  libopenimageio-dev openimageio-tools libopenexr-dev
  libopencolorio-dev
  libfftw3-dev
  pybind11-dev python3-dev python3-numpy python3-matplotlib
  libgtest-dev libgmock-dev libbenchmark-dev
  blender
  # The viewport test: Blender with a window on Xvfb and Mesa's software OpenGL.
  xvfb xauth libgl1-mesa-dri libglx-mesa0
  # The render farm's localhost test (tests/farm): a private single-node Slurm (auth/none, so
  # the MUNGE daemon the package brings is not started).
  slurm-wlm
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "setup-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
