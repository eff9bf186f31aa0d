# Shared by scripts/mukca_compare.sh, mukca_pooled.sh and mukca_as_authors.sh
# (sourced): the authors' calibrated URDF of a recording folder, the evaluate
# JSON as a table row, the import of every recording of one robot, and the
# calibration from the nominal Panda.

authors_of() {  # recording folder -> calibrated_urdf folder
  case $1 in
    panda_2_clean) echo panda_2 ;; panda_3 | panda_3_bis) echo panda_3 ;;
    panda_4_clean) echo panda_4 ;; *) echo "$1" ;;
  esac
}

stats() {  # evaluate JSON -> "rms hole_0 hole_1 distance_error"
  python3 -c '
import json,sys
try: j=json.load(sys.stdin)
except Exception: print("NA\tNA\tNA\tNA"); sys.exit()
f=j["fixed_points"]; d=j["point_distances"][0]["distance_mm"]-50
print("%.4f\t%.4f\t%.4f\t%+.4f" % (j["rms_mm"], f["hole_0"]["rms_mm"], f["hole_1"]["rms_mm"], d))'
}

# import_recordings KINCAL ROBOT_DIR PREFIX: every recording of the robot as
# PREFIX<recording>.csv; their names in the array `recs`.
import_recordings() {
  recs=()
  local rec r
  for rec in "$2"/*/; do
    r=$(basename "$rec")
    "$1" import mukca --dir "$rec" --out "$3$r.csv" >/dev/null
    recs+=("$r")
  done
}

# calibrate_nominal KINCAL MUKCA_DIR OUT.yaml CALIBRATE_ARGS...: kincal
# calibrate from the nominal Panda (ball_link tip, no hold-out, CAL_ARGS
# from the environment passed through; NOMINAL_URDF replaces the nominal
# urdf/panda.urdf, e.g. a copy with <inertial> elements); prints
# "train_rms free passes".
calibrate_nominal() {
  local k=$1 m=$2 out=$3
  shift 3
  "$k" calibrate --robot "${NOMINAL_URDF:-$m/urdf/panda.urdf}" --tip ball_link ${CAL_ARGS:-} \
    "$@" --holdout 0 --out "$out" --json |
    python3 -c 'import json,sys
try: j=json.load(sys.stdin)
except Exception: print("NA\tNA\tNA"); sys.exit()
print("%.4f\t%d\t%d" % (j["train_rms_mm"], len(j["identifiable"]), j["identifiability_passes"]))'
}
