#!/usr/bin/env bash
# Installs what omniloop needs beyond a Rust toolchain: Mesa's software Vulkan driver
# (lavapipe) and the Vulkan loader, so that the wgpu renderer finds an adapter on machines
# without a GPU. Skips packages that are already installed.
set -euo pipefail

packages=(mesa-vulkan-drivers libvulkan1)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "omniloop: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if ! command -v cargo >/dev/null 2>&1; then
  echo "omniloop: cargo not found; install Rust 1.95 or newer from https://rustup.rs" >&2
  exit 1
fi

# The Python tests run in a virtual environment of their own (scripts/test.sh makes it).
if ! command -v python3 >/dev/null 2>&1 || ! python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
  echo "omniloop: installing python3 and python3-venv for the Python package's tests"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends python3 python3-venv
fi
