#!/usr/bin/env bash
# Behaviour check for refactorings: runs a fixed list of commands with one
# kincal binary directory and writes every JSON output (and the written model
# files) into OUT, so that two builds can be compared:
#
#   scripts/same_outputs.sh BEFORE_BIN_DIR /tmp/before
#   scripts/same_outputs.sh build/bin /tmp/after
#   scripts/same_outputs.sh --compare /tmp/before /tmp/after
#
# The comparison ignores times (keys ending in "seconds"), command lines,
# output paths and the "kincal ..." line every written file records; numbers
# must agree to 1e-9 relative, text byte for byte. The list: the demo (calibrate,
# clearance, diagnose model, evaluate, export urdf, report), UR10 series C
# diagnose model (needs ../shared/data), a rendered BH-7 session (simulate
# --render, track, bundle, report on the bundle), camcal on the shared
# stereo pairs.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--compare" ]; then
  python3 - "$2" "$3" <<'EOF'
import json, math, os, re, sys
a_dir, b_dir = sys.argv[1], sys.argv[2]
# Numbers agree when within 1e-9 relative: the bundle's multi-threaded
# Ceres solve differs run to run in the 13th digit.
def close(x, y):
    return x == y or abs(x - y) <= 1e-9 * max(abs(x), abs(y))
def same(x, y):
    if isinstance(x, dict) and isinstance(y, dict):
        kx = {k for k in x if not ignored(k)}
        ky = {k for k in y if not ignored(k)}
        return kx == ky and all(same(x[k], y[k]) for k in kx)
    if isinstance(x, list) and isinstance(y, list):
        return len(x) == len(y) and all(same(a, b) for a, b in zip(x, y))
    if isinstance(x, (int, float)) and isinstance(y, (int, float)) \
            and not isinstance(x, bool) and not isinstance(y, bool):
        return close(x, y)
    return x == y
def ignored(k):
    return k.endswith("seconds") or k in ("command", "out", "out_obs", "poses", "bytes")
def text(path, root):
    s = open(path, errors="replace").read().replace(root, "<OUT>")
    s = re.sub(r"kincal [a-z][^\n\"<]*", "kincal <command>", s)
    s = re.sub(r"[0-9.]+(e-?[0-9]+)? ?s\b", "<t> s", s)
    return s
bad = 0
names = sorted(n for n in set(os.listdir(a_dir)) | set(os.listdir(b_dir)) if n != "work")
for n in names:
    pa, pb = os.path.join(a_dir, n), os.path.join(b_dir, n)
    if not (os.path.exists(pa) and os.path.exists(pb)):
        print(f"MISSING   {n}"); bad += 1; continue
    if n.endswith(".json"):
        try:
            ok = same(json.load(open(pa)), json.load(open(pb)))
        except json.JSONDecodeError as e:
            ok = open(pa).read() == open(pb).read()
    else:
        ok = text(pa, a_dir) == text(pb, b_dir)
    print(("same      " if ok else "DIFFERENT ") + n)
    bad += 0 if ok else 1
print(f"{len(names) - bad}/{len(names)} outputs identical")
sys.exit(1 if bad else 0)
EOF
  exit $?
fi

BIN=$(cd "$1" && pwd)
OUT=$2
K=$BIN/kincal
mkdir -p "$OUT"
T=$OUT/work
rm -rf "$T"; mkdir -p "$T"
S=data/sessions/bh7_demo
SHARED=${KINCAL_SHARED_DATA:-../shared/data}

# run NAME CMD...: the command's stdout into OUT/NAME (exit code recorded too).
run() {
  local name=$1; shift
  set +e
  "$@" >"$OUT/$name" 2>"$T/$name.err"
  echo $? >"$OUT/$name.rc"
  set -e
}

echo "== demo"
run calibrate.json $K calibrate --robot $S/robot.yaml --obs $S/observations.csv --out "$OUT/calibrated.yaml" --json
run clearance.json $K diagnose clearance --robot "$OUT/calibrated.yaml" --obs $S/observations.csv --gamma 3 --json
run diagnose.json $K diagnose model --robot $S/robot.yaml --obs $S/observations.csv --out "$OUT/extended.yaml" --json
run evaluate.json $K evaluate --robot "$OUT/extended.yaml" --obs $S/observations.csv --json
run export.json $K export urdf --robot "$OUT/calibrated.yaml" --out "$OUT/calibrated.urdf" --json
run report.json $K report --robot $S/robot.yaml --obs $S/observations.csv \
  --calibrated "$OUT/extended.yaml" --diagnosis "$OUT/diagnose.json" --out "$OUT/report.html" --json

if [ -d "$SHARED/ipa-robot-accuracy" ]; then
  echo "== UR10 series C"
  $K import ipa-ur10 --in "$SHARED/ipa-robot-accuracy/Series_C/measurements_random_poses.csv" --out "$T/C.csv" >/dev/null
  run ur10_c_diagnose.json $K diagnose model --robot data/robots/ur10.yaml --obs "$T/C.csv" --out "$OUT/ur10_c.yaml" --json
else
  echo "== UR10 series C skipped: $SHARED/ipa-robot-accuracy absent"
fi

echo "== rendered BH-7 session: track, bundle, report"
$BIN/kincal simulate --robot data/robots/bh7.yaml --out "$T/S" --poses 80 --noise 0 --seed 11 \
  --effect backlash:j3:0.05 --render --render-width 640 --render-height 512 \
  --render-noise 1.5 --render-blur 0.5 >/dev/null
run track.json $K track --rig "$T/S/rig.yaml" --target "$T/S/target.yaml" \
  --left "$T/S/session/left/*.png" --right "$T/S/session/right/*.png" --out "$OUT/points.csv" --json
run bundle.json $K bundle --robot "$T/S/robot.yaml" --rig "$T/S/rig.yaml" --target "$T/S/target.yaml" \
  --session "$T/S/session" --out "$OUT/bundle_cal.yaml" --out-obs "$OUT/bundle_seen.csv" --extensions backlash --json
run report_bundle.json $K report --robot "$T/S/robot.yaml" --obs "$OUT/bundle_seen.csv" \
  --calibrated "$OUT/bundle_cal.yaml" --session "$T/S/session" --rig "$T/S/rig.yaml" --out "$OUT/report_bundle.html" --json

if [ -d "$SHARED/opencv-stereo-left-right" ]; then
  echo "== camcal on the shared stereo pairs"
  D=$SHARED/opencv-stereo-left-right
  run camcal_stereo.json $K camcal --left "$D/left*.jpg" --right "$D/right*.jpg" \
    --target chessboard:9x6:1 --out "$OUT/rig.yaml" --json
fi
echo "outputs in $OUT"
