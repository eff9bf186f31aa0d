#!/bin/bash
# Leave-one-recording-out on the MUKCa Pandas (docs/REAL_DATA.md): for each
# recording, calibrate from the NOMINAL Panda on ALL the robot's other
# recordings pooled (each recording's sockets are their own fixed points,
# each pair 50 mm apart), then evaluate on the left-out recording beside the
# authors' calibrated URDF on the same poses.
# Usage: scripts/mukca_pooled.sh [kincal binary] [mukca dir] [robot glob] > table.tsv
set -uo pipefail
K=${1:-build/bin/kincal}
M=${2:-../shared/data/mukca}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
. "$(dirname "$0")/mukca_common.sh"
printf "robot\ttest\tkincal_rms\tkincal_h0\tkincal_h1\tkincal_dist_err\tauthors_rms\tauthors_h0\tauthors_h1\tauthors_dist_err\tkincal_train_rms\tfree\n"
for robot_dir in "$M"/data/${3:-panda_*}; do
  robot=$(basename "$robot_dir")
  authors="$M/calibrated_urdf/$(authors_of "$robot")/panda.urdf"
  import_recordings "$K" "$robot_dir" "$W/"
  for test in "${recs[@]}"; do
    pooled="$W/pooled.csv"
    dist=()
    grep -m1 '^pose,' "$W/${recs[0]}.csv" >"$pooled"
    for r in "${recs[@]}"; do
      [ "$r" = "$test" ] && continue
      grep -v '^#' "$W/$r.csv" | tail -n +2 |
        sed -E "s/,(hole_[01])\$/,${r}_\1/; s/^([^,]*),/${r}_\1,/" >>"$pooled"
      dist+=(--fixed-distance "${r}_hole_0,${r}_hole_1,50")
    done
    cal=$("$K" calibrate --robot "$M/urdf/panda.urdf" --tip ball_link ${CAL_ARGS:-} \
      --obs "$pooled" "${dist[@]}" --holdout 0 --out "$W/cal.yaml" --json |
      python3 -c 'import json,sys
try: j=json.load(sys.stdin)
except Exception: print("NA\tNA\tNA"); sys.exit()
print("%.4f\t%d" % (j["train_rms_mm"], len(j["identifiable"])))')
    ours=$("$K" evaluate --robot "$W/cal.yaml" --obs "$W/$test.csv" --json | stats)
    theirs=$("$K" evaluate --robot "$authors" --tip ball_link --obs "$W/$test.csv" --json | stats)
    printf "%s\t%s\t%s\t%s\t%s\n" "$robot" "$test" "$ours" "$theirs" "$cal"
  done
done
