#!/bin/bash
# Honest comparison on the MUKCa Panda recordings (docs/REAL_DATA.md): for
# every recording, calibrate from the NOMINAL Panda (urdf/panda.urdf) with
# the 50 mm socket distance, then evaluate on the robot's other recordings;
# the authors' calibrated URDF is evaluated on the same poses.
# Usage: scripts/mukca_compare.sh [kincal binary] [mukca dir] [robot glob] > table.tsv
set -uo pipefail
K=${1:-build/bin/kincal}
M=${2:-../shared/data/mukca}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
. "$(dirname "$0")/mukca_common.sh"
printf "robot\ttrain\ttest\tkincal_rms\tkincal_h0\tkincal_h1\tkincal_dist_err\tauthors_rms\tauthors_h0\tauthors_h1\tauthors_dist_err\tkincal_train_rms\tfree\tpasses\n"
for robot_dir in "$M"/data/${3:-panda_*}; do
  robot=$(basename "$robot_dir")
  authors="$M/calibrated_urdf/$(authors_of "$robot")/panda.urdf"
  import_recordings "$K" "$robot_dir" "$W/$robot."
  declare -A theirs=()  # the authors' model on each recording, once
  for test in "${recs[@]}"; do
    theirs[$test]=$("$K" evaluate --robot "$authors" --tip ball_link --obs "$W/$robot.$test.csv" --json | stats)
  done
  for train in "${recs[@]}"; do
    cal=$(calibrate_nominal "$K" "$M" "$W/cal.yaml" \
      --obs "$W/$robot.$train.csv" --fixed-distance hole_0,hole_1,50)
    for test in "${recs[@]}"; do
      [ "$test" = "$train" ] && continue
      ours=$("$K" evaluate --robot "$W/cal.yaml" --obs "$W/$robot.$test.csv" --json | stats)
      printf "%s\t%s\t%s\t%s\t%s\t%s\n" "$robot" "$train" "$test" "$ours" "${theirs[$test]}" "$cal"
    done
  done
done
