#!/usr/bin/env bash
# Configures and builds kincal into build/ (the CLI lands in build/bin/kincal).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=${JOBS:-$(nproc)}
LAUNCHER=()
# ccache, when installed, makes rebuilds across checkouts cheap; CI has none.
command -v ccache >/dev/null && LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${LAUNCHER[@]}" "$@" >/dev/null
cmake --build build -j "$JOBS"
