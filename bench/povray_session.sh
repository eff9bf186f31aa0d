#!/usr/bin/env bash
# The tracker and the bundle on a session rendered by POV-Ray, a ray tracer
# we did not write (Debian package `povray`): the same poses, rig (without
# lens distortion) and target as `kincal simulate --render`, but images whose
# antialiasing, texture sampling, shading and shadows share nothing with
# synth/render.cc (bench/povray_scene.cc writes the scenes). Prints the
# tracked tips against the truth for both renders, and both bundles' robots
# at fresh poses (docs/VISION.md, "A renderer we did not write").
#
#   bench/povray_session.sh [ROBOT_ARGS] [SEED] [POSES] [WORK_DIR]
#   e.g. bench/povray_session.sh "--robot data/robots/bh7.yaml" 7 120 /tmp/pov
# Environment: LIGHT_DEG (area light direction, default 35), LIGHT_DISTANCE
# (times the target's depth, default 1.1), NOISE (read
# noise, levels, default 1.0), GAMMA (POV-Ray's File_Gamma, default 1.0 =
# linear sensor), WIDTH / HEIGHT (default 640 x 512), AA (POV-Ray's
# antialiasing, default "+A0.02 +AM2 +R3": adaptive, up to 3 x 3 per pixel).
set -euo pipefail
cd "$(dirname "$0")/.."
ROBOT_ARGS=${1:-"--robot data/robots/bh7.yaml"}
SEED=${2:-7}
POSES=${3:-120}
WORK=${4:-$(mktemp -d)}
K=${KINCAL:-build/bin/kincal}
P_SCENE=${POVRAY_SCENE:-build/bin/povray_scene}
WIDTH=${WIDTH:-640}
HEIGHT=${HEIGHT:-512}
FRESH=200
command -v povray >/dev/null || { echo "povray not found: apt-get install povray" >&2; exit 2; }
mkdir -p "$WORK"
S="$WORK/sim"
P="$WORK/pov"
rm -rf "$S" "$P"
# shellcheck disable=SC2086
"$K" simulate $ROBOT_ARGS --out "$WORK/fresh_all" --poses $((POSES + FRESH)) \
  --noise 0 --seed "$SEED" >/dev/null
awk -v skip="$POSES" '/^#/ {print; next} !h {print; h = 1; next} ++n > skip' \
  "$WORK/fresh_all/observations.csv" >"$WORK/fresh.csv"
# shellcheck disable=SC2086
"$K" simulate $ROBOT_ARGS --out "$S" --poses "$POSES" --noise 0 --seed "$SEED" \
  --render --render-noise "${NOISE:-1.0}" --render-width "$WIDTH" \
  --render-height "$HEIGHT" >/dev/null
"$P_SCENE" scene --sim "$S" --out "$P" --light-deg "${LIGHT_DEG:-35}" \
  --light-distance "${LIGHT_DISTANCE:-1.1}"
for f in "$P"/pov/*_*.pov; do
  b=$(basename "$f" .pov)
  cam=${b%_*}
  mkdir -p "$P/raw/$cam"
  echo "$f $P/raw/$cam/${b##*_}.png"
done | xargs -P 1 -n 2 sh -c 'cd "$(dirname "$0")" && povray +I"$(basename "$0")" +O"$1" \
  +W'"$WIDTH"' +H'"$HEIGHT"' +FN8 -D '"${AA:-+A0.02 +AM2 +R3}"' +J Display=off \
  File_Gamma='"${GAMMA:-1.0}"' -V -GA >/dev/null 2>&1 ||
  { echo "povray failed on $0" >&2; exit 255; }'
"$P_SCENE" finish --out "$P" --noise "${NOISE:-1.0}" --seed "$SEED"

rms() { "$K" evaluate --robot "$1" --obs "$WORK/fresh.csv" --json |
  python3 -c 'import json, sys; print("%.4f" % json.load(sys.stdin)["rms_mm"])'; }
for R in "$S" "$P"; do
  "$K" track --rig "$R/rig.yaml" --target "$R/target.yaml" \
    --session "$R/session" --out "$R/pts.csv" --quiet >/dev/null
  echo "$(basename "$R"): $("$P_SCENE" score --out "$R" --points "$R/pts.csv")"
  "$K" bundle --robot "$S/robot.yaml" --rig "$R/rig.yaml" \
    --target "$R/target.yaml" --session "$R/session" --out "$R/b.yaml" \
    --quiet --json >"$R/b.json"
  echo "$(basename "$R"): bundle robot at $FRESH fresh poses $(rms "$R/b.yaml") mm"
done
echo "nominal robot: $(rms "$WORK/fresh_all/robot.yaml") mm; sessions in $WORK"
