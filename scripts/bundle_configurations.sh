#!/usr/bin/env bash
# The bundle against the two-step pipeline (track -> calibrate) on rendered
# sessions of one robot in every camera configuration (docs/BUNDLE.md):
# cameras on a stand (1, 2, 3) and on the flange (1, 2, 3), the same seed,
# poses and hidden true robot. Both robots are judged by `kincal evaluate`
# on noise-free true tool-row ends at fresh poses (rows POSES.. of a longer
# simulate run of the same seed), printed as a markdown table.
#
#   scripts/bundle_configurations.sh [ROBOT_ARGS] [SEED] [POSES] [WORK_DIR]
#   e.g. scripts/bundle_configurations.sh "--robot data/robots/bh7.yaml" 7 120
#        scripts/bundle_configurations.sh \
#          "--robot ../shared/data/mukca/urdf/panda.urdf --tip panda_hand" 3 150
set -euo pipefail
cd "$(dirname "$0")/.."
ROBOT_ARGS=${1:-"--robot data/robots/bh7.yaml"}
SEED=${2:-7}
POSES=${3:-120}
WORK=${4:-$(mktemp -d)}
K=${KINCAL:-build/bin/kincal}
FRESH=200
mkdir -p "$WORK"
# shellcheck disable=SC2086
"$K" simulate $ROBOT_ARGS --out "$WORK/fresh_all" --poses $((POSES + FRESH)) \
  --noise 0 --seed "$SEED" >/dev/null
# Fresh poses: every row after the first POSES (comments and header kept).
awk -v skip="$POSES" '/^#/ {print; next} !h {print; h = 1; next} ++n > skip' \
  "$WORK/fresh_all/observations.csv" >"$WORK/fresh.csv"

rms() { "$K" evaluate --robot "$1" --obs "$WORK/fresh.csv" --json |
  python3 -c 'import json, sys; print("%.3f" % json.load(sys.stdin)["rms_mm"])'; }

echo "| mount | cameras | frames used | bundle, fresh mm | track -> calibrate, fresh mm |"
echo "| --- | --- | --- | --- | --- |"
for mount in world flange; do
  for n in 1 2 3; do
    S="$WORK/$mount$n"
    rm -rf "$S"
    # shellcheck disable=SC2086
    "$K" simulate $ROBOT_ARGS --out "$S" --poses "$POSES" --noise 0 \
      --seed "$SEED" --render --render-mount "$mount" --render-cameras "$n" \
      --render-noise 1.5 --render-blur 0.5 --render-width 640 \
      --render-height 512 >/dev/null
    "$K" bundle --robot "$S/robot.yaml" --rig "$S/rig.yaml" \
      --target "$S/target.yaml" --session "$S/session" --out "$S/b.yaml" \
      --quiet --json >"$S/b.json"
    used=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["used_frames"])' "$S/b.json")
    two="-"
    if "$K" track --rig "$S/rig.yaml" --target "$S/target.yaml" \
         --session "$S/session" --robot "$S/robot.yaml" --out "$S/pts.csv" \
         --out-obs "$S/tracked.csv" >/dev/null 2>&1 &&
       "$K" calibrate --robot "$S/robot.yaml" --obs "$S/tracked.csv" \
         --out "$S/t.yaml" >/dev/null 2>&1; then
      two=$(rms "$S/t.yaml")
    fi
    echo "| $mount | $n | $used | $(rms "$S/b.yaml") | $two |"
  done
done
echo "nominal robot: $(rms "$WORK/fresh_all/robot.yaml") mm; sessions in $WORK"
