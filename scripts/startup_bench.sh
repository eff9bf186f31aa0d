#!/usr/bin/env bash
# Whole-process start-up of kincal (docs/STARTUP.md): shared libraries loaded,
# and wall / CPU time of `--version`, `--help`, `calibrate` on the 240 poses
# of data/sessions/bh7_demo and an image command's `--help` (front end + exec
# into kincal-vision). With --before BINARY (e.g. a kincal built before the
# split) both are measured in the same run, runs interleaved, so that a
# machine whose load changes treats them alike.
# Usage: scripts/startup_bench.sh [--before BINARY] [--runs N] [AFTER_BINARY]
#        (AFTER_BINARY default build/bin/kincal; N default 20)
set -euo pipefail
cd "$(dirname "$0")/.."
BEFORE="" RUNS=20 AFTER=build/bin/kincal
while [ $# -gt 0 ]; do
  case $1 in
    --before) BEFORE=$2; shift 2 ;;
    --runs) RUNS=$2; shift 2 ;;
    *) AFTER=$1; shift ;;
  esac
done
BINS=("$AFTER")
[ -n "$BEFORE" ] && BINS=("$BEFORE" "$AFTER")
D=data/sessions/bh7_demo
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# One run: "wall user+sys" in ms (bash's `time`, no other tool needed).
run_once() {
  local TIMEFORMAT='%3R %3U %3S' t
  t=$({ time "$@" >/dev/null 2>&1; } 2>&1 | tail -1)
  awk '{printf "%.1f %.1f\n", $1 * 1000, ($2 + $3) * 1000}' <<<"$t"
}

# Median and minimum of a column of numbers.
stats() {
  sort -n | awk '{v[NR] = $1} END {
    m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
    printf "%7.1f %7.1f", m, v[1]}'
}

echo "kincal start-up, $RUNS runs each, runs interleaved; $(nproc) cores," \
  "load average $(cut -d' ' -f1-3 /proc/loadavg)"
for b in "${BINS[@]}"; do
  echo "  $b: $(ldd "$b" | wc -l) shared libraries"
done
printf '%-34s %-10s %15s %15s\n' "command" "binary" "wall ms med/min" \
  "cpu ms med/min"
measure() {  # label, args...
  local label=$1
  shift
  local i k
  rm -f "$tmp"/times_*
  for ((i = 0; i < RUNS; i++)); do
    for k in "${!BINS[@]}"; do
      run_once "${BINS[$k]}" "$@" >>"$tmp/times_$k"
    done
  done
  for k in "${!BINS[@]}"; do
    local name=after
    [ -n "$BEFORE" ] && [ "$k" = 0 ] && name=before
    printf '%-34s %-10s %s %s\n' "$label" "$name" \
      "$(cut -d' ' -f1 "$tmp/times_$k" | stats)" \
      "$(cut -d' ' -f2 "$tmp/times_$k" | stats)"
  done
}
measure "--version" --version
measure "--help" --help
measure "calibrate (240 poses)" calibrate --robot $D/robot.yaml \
  --obs $D/observations.csv --out "$tmp/cal.yaml"
measure "track --help (image command)" track --help
