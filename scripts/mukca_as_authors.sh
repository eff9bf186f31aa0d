#!/bin/bash
# Like for like with the MUKCa authors (docs/REAL_DATA.md): kincal
# calibrates from the NOMINAL Panda on the one recording the authors trained
# their calibrated URDF on, then both models are evaluated on every other
# recording of that robot (panda_3's model also on panda_3_bis, the same
# arm). panda_6: `front`, their config.yaml; panda_2 / 3 / 4: the recording
# where their model's 50 mm error is ~0.001 mm and its scatter lowest (a
# training figure; every other recording shows >= 0.008 mm), see the doc.
# Usage: scripts/mukca_as_authors.sh [kincal binary] [mukca dir] > table.tsv
set -uo pipefail
K=${1:-build/bin/kincal}
M=${2:-../shared/data/mukca}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
. "$(dirname "$0")/mukca_common.sh"
printf "robot\ttrain\ttest\tkincal_rms\tkincal_h0\tkincal_h1\tkincal_dist_err\tauthors_rms\tauthors_h0\tauthors_h1\tauthors_dist_err\tkincal_train_rms\tfree\tpasses\n"
# model  training recording  robots whose recordings are tested; SPECS (one
# spec per line) replaces them, e.g. for a copy of the authors' repository
# with more robots: SPECS="panda_7 panda_7/front panda_7" (their
# calibrated_urdf/panda_7/config.yaml names the training recording).
DEFAULT_SPECS="panda_2 panda_2_clean/front_center panda_2_clean
panda_3 panda_3/frontcenter panda_3 panda_3_bis
panda_4 panda_4_clean/front panda_4_clean
panda_6 panda_6/front panda_6"
mapfile -t specs <<<"${SPECS:-$DEFAULT_SPECS}"
for spec in "${specs[@]}"; do
  [ -z "$spec" ] && continue
  set -- $spec
  model=$1 train=$2
  shift 2
  authors="$M/calibrated_urdf/$model/panda.urdf"
  "$K" import mukca --dir "$M/data/$train" --out "$W/train.csv" >/dev/null
  cal=$(calibrate_nominal "$K" "$M" "$W/cal.yaml" --obs "$W/train.csv" \
    --fixed-distance hole_0,hole_1,50)
  for robot in "$@"; do
    import_recordings "$K" "$M/data/$robot" "$W/$robot."
    for test in "${recs[@]}"; do
      [ "$robot/$test" = "$train" ] && continue
      ours=$("$K" evaluate --robot "$W/cal.yaml" --obs "$W/$robot.$test.csv" --json | stats)
      theirs=$("$K" evaluate --robot "$authors" --tip ball_link --obs "$W/$robot.$test.csv" --json | stats)
      printf "%s\t%s\t%s\t%s\t%s\t%s\n" "$robot" "${train#*/}" "$test" "$ours" "$theirs" "$cal"
    done
  done
done
