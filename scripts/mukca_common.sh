# Shared by scripts/mukca_compare.sh and scripts/mukca_pooled.sh (sourced):
# the authors' calibrated URDF of a recording folder, the evaluate JSON as a
# table row, and the import of every recording of one robot.

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
