#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (ctest). Real-data
# tests read ../shared/data and skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/progress.sh
step "Set-up: Debian packages (scripts/setup.sh; a no-op when present)"
scripts/setup.sh
step "Build (cmake + make; log in build.log; warnings are errors when KINCAL_WERROR=ON, as in CI)"
build_quietly -DKINCAL_WERROR="${KINCAL_WERROR:-OFF}"
step "Tests (ctest; real-data tests skip when ../shared/data is absent)"
cd build
ctest --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
