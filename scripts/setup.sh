#!/usr/bin/env bash
# Installs every Debian package kincal needs. Idempotent: a no-op when all are present.
# Usage (as root on Debian 12): scripts/setup.sh
set -euo pipefail
PKGS=(
  build-essential cmake pkg-config git
  libopencv-dev libapriltag-dev libceres-dev libeigen3-dev
  libv4l-dev libaravis-dev libusb-1.0-0-dev
  libpng-dev libcairo2-dev poppler-utils povray
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libtinyxml2-dev liburdfdom-dev liburdfdom-tools
  chromium clang libclang-rt-14-dev
  libgtest-dev libgmock-dev libbenchmark-dev
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PKGS[@]} packages present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
