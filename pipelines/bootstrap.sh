#!/usr/bin/env bash
# Installs what the toolchain needs from Debian 12's packages (only when something is
# missing, so re-running is cheap) and builds the tools into build/bin (Release); the tests are
# built by tests/run.sh. Used by the README's two commands; safe to run again at any time.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  cmake g++ make pkg-config git
  libtinygltf-dev libstb-dev libglm-dev libopenexr-dev openexr libopenimageio-dev openimageio-tools
  libosmesa6-dev libembree-dev libtbb-dev libcli11-dev nlohmann-json3-dev libpng-dev
  libgtest-dev libbenchmark-dev ffmpeg python3 gnuplot-nox
)

pipelines/apt_install.sh "${packages[@]}"

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs" --target tools
