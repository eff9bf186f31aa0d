#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (ctest). Real-data
# tests read ../shared/data and skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
cd build
ctest --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
