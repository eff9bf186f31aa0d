#!/usr/bin/env bash
# libFuzzer runs of every file parser (fuzz/). Builds build-fuzz/ with clang,
# -fsanitize=fuzzer-no-link,address,undefined, seeds each corpus from the
# project's own files, runs each target for SECONDS (default 60) with nice,
# and prints the run counts. A crash leaves crash-* / leak-* / timeout-* in
# build-fuzz/findings/<target>/ and makes the script exit 1: turn it into a
# regression test.
# Usage: scripts/fuzz.sh [SECONDS] [target ...]   (targets: robot_yaml urdf
#        observations_csv rig_yaml target_yaml session_frames_csv
#        session_folder joint_log targets_csv cameramodel; default: all)
# The figures of the last long runs are in docs/FUZZING.md.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET=${1:-60}
shift || true
TARGETS=("$@")
ALL=(robot_yaml urdf observations_csv rig_yaml target_yaml session_frames_csv
  session_folder joint_log targets_csv cameramodel)
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=("${ALL[@]}")
B=build-fuzz
CC=clang CXX=clang++ cmake -S . -B $B -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DKINCAL_FUZZ=ON -DKINCAL_BUILD_TESTS=OFF -DKINCAL_BUILD_BENCH=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined" \
  $(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) >/dev/null
seeds() {  # target -> seed files (fuzz/seeds/<target>/ plus project files)
  ls fuzz/seeds/$1/* 2>/dev/null || true
  case $1 in
    robot_yaml) ls data/robots/*.yaml data/sessions/*/robot.yaml ;;
    urdf) ls data/robots/*.urdf ;;
    observations_csv) ls data/sessions/*/observations.csv ;;
    rig_yaml) find . -path ./build\* -prune -o -name 'rig*.yaml' -print ;;
    target_yaml) find . -path ./build\* -prune -o -name 'target*.yaml' -print ;;
    session_frames_csv) find . -path ./build\* -prune -o -name 'frames.csv' -print ;;
    joint_log) find . -path ./build\* -prune -o -name 'joints*.csv' -print ;;
  esac
}
status=0
for t in "${TARGETS[@]}"; do
  cmake --build $B -j1 --target fuzz_$t >/dev/null
  corpus=$B/corpus/$t findings=$B/findings/$t
  mkdir -p "$corpus" "$findings"
  for f in $(seeds $t); do cp "$f" "$corpus/" 2>/dev/null || true; done
  log=$B/findings/$t.log
  if ! nice $B/bin/fuzz_$t "$corpus" -max_total_time="$SECONDS_PER_TARGET" \
      -max_len=16384 -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$findings/" \
      >"$log" 2>&1; then
    echo "fuzz_$t: FINDING, see $findings/ and $log"
    status=1
  fi
  runs=$(grep -o 'Done [0-9]* runs' "$log" | tail -1 || true)
  echo "fuzz_$t: ${runs:-no summary} in ${SECONDS_PER_TARGET} s"
done
exit $status
