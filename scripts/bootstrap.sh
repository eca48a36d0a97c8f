#!/usr/bin/env bash
# Installs the Debian packages the build needs (only the missing ones) and
# configures + builds everything into build/. Safe to run repeatedly.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(g++ cmake ninja-build libfmt-dev nlohmann-json3-dev libcli11-dev libgtest-dev libabsl-dev
          python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib python3-distributed libpng-dev libgif-dev libfreetype-dev fonts-dejavu-core libssl-dev
          python3-venv python3-pip python3-setuptools python3-wheel python3-mypy
          clang-14 libclang-rt-14-dev libfuzzer-14-dev chromium chromium-driver python3-selenium
          libclang-14-dev libclang-cpp14-dev liblld-14-dev llvm-14-dev zlib1g-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "bootstrap: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
ninja -C build
