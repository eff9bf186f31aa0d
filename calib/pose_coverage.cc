#include "calib/pose_coverage.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <sstream>

#include "calib/chain.h"
#include "calib/fit.h"
#include "calib/identifiability.h"
#include "calib/model_state.h"
#include "data/error.h"

namespace kincal {

namespace {

// The rows with a measured tip (calibrate's kMeasured rows).
Observations RowsWithTips(const Observations& obs) {
  Observations out;
  out.source = obs.source;
  out.joint_names = obs.joint_names;
  for (const Observation& o : obs.rows) {
    if (o.has_point) out.rows.push_back(o);
  }
  return out;
}

// The joints' seen travel against their ranges.
std::vector<JointTravel> Travel(const Robot& robot, const Observations& obs,
                                double small_fraction) {
  std::vector<JointTravel> out;
  for (size_t j = 0; j < robot.joints.size(); ++j) {
    const RobotRow& row = robot.joints[j];
    JointTravel t;
    t.joint = row.name;
    double lo = INFINITY, hi = -INFINITY;
    for (const Observation& o : obs.rows) {
      lo = std::min(lo, o.q[j]);
      hi = std::max(hi, o.q[j]);
    }
    t.seen = hi >= lo ? hi - lo : 0;
    t.range = row.HasLimits()                    ? row.upper - row.lower
              : row.type == JointType::kRevolute ? 360.0
                                                 : 0.0;
    t.small = t.range > 0 && t.seen < small_fraction * t.range;
    out.push_back(t);
  }
  return out;
}

// `n` poses drawn uniformly over the joints' limits (a revolute joint
// without limits over +-180 deg; a prismatic one over its seen readings),
// each with a placeholder tip: the scan reads joint values only.
Observations ReferencePoses(const Robot& robot, const Observations& data, int n,
                            uint64_t seed) {
  std::mt19937_64 rng(seed);
  Observations out;
  out.source = "reference poses";
  out.joint_names = data.joint_names;
  for (int i = 0; i < n; ++i) {
    Observation o;
    o.pose = "ref" + std::to_string(i);
    o.has_point = true;
    for (size_t j = 0; j < robot.joints.size(); ++j) {
      const RobotRow& row = robot.joints[j];
      double lo = -180, hi = 180;
      if (row.HasLimits()) {
        lo = row.lower;
        hi = row.upper;
      } else if (row.type != JointType::kRevolute) {
        lo = hi = data.rows[i % data.rows.size()].q[j];
      }
      o.q.push_back(std::uniform_real_distribution<double>(lo, hi)(rng));
    }
    out.rows.push_back(o);
  }
  return out;
}

// The geometry parameters (and the frame's) that poses `obs` determine.
std::set<std::string> Determined(const Chain& chain, const Observations& obs,
                                 const IdentifiabilityOptions& options) {
  ModelState state;
  state.chain = chain;
  const std::vector<Measurement> ms = MakeMeasurements(chain, obs, &state);
  std::vector<ParamInfo> candidates = AllFrameParams(state);
  for (const ParamInfo& p : GeometryParams(chain)) candidates.push_back(p);
  const Identifiability id =
      AnalyzeIdentifiability(ms, state, candidates, options);
  std::set<std::string> out;
  for (const ParamInfo& p : id.identifiable) out.insert(p.name);
  for (const std::string& w : id.weak) out.erase(w);
  return out;
}

}  // namespace

void PoseCoverageOptions::Check() const {
  auto fail = [](const char* what, double v) {
    std::ostringstream os;
    os << "pose coverage option " << what << " = " << v;
    throw InputError(os.str());
  };
  if (!(noise_sigma_mm > 0))
    fail("noise_sigma_mm (expected > 0)", noise_sigma_mm);
  if (!(small_travel_fraction > 0 && small_travel_fraction <= 1)) {
    fail("small_travel_fraction (expected in (0, 1])", small_travel_fraction);
  }
}

PoseCoverage CheckPoseCoverage(const Robot& nominal, const Observations& obs,
                               const PoseCoverageOptions& options) {
  options.Check();
  PoseCoverage out;
  const Observations data = RowsWithTips(obs);
  if (data.rows.size() < 2) return out;
  out.travel = Travel(nominal, data, options.small_travel_fraction);
  const Chain chain = Chain::FromRobot(nominal);
  IdentifiabilityOptions id;
  id.noise_sigma_mm = options.noise_sigma_mm;
  const std::set<std::string> seen = Determined(chain, data, id);
  // As many reference poses as the data have: the criterion's sigma
  // scales with 1 / sqrt(poses), so both scans see the same count.
  const Observations reference = ReferencePoses(
      nominal, data, static_cast<int>(data.rows.size()), options.seed);
  for (const std::string& p : Determined(chain, reference, id)) {
    if (!seen.count(p)) out.undetermined.push_back(p);
  }
  return out;
}

std::string PoseCoverageMessage(const PoseCoverage& coverage) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(1);
  os << "the poses with a tip leave " << coverage.undetermined.size()
     << " robot parameter(s) undetermined that poses over the joints' "
        "limits would determine (";
  for (size_t i = 0; i < coverage.undetermined.size(); ++i) {
    os << (i ? ", " : "") << coverage.undetermined[i];
  }
  os << "); joint travel seen: ";
  bool first = true;
  for (const JointTravel& t : coverage.travel) {
    os << (first ? "" : ", ") << t.joint << " " << t.seen;
    if (t.range > 0) os << " of " << t.range;
    if (t.small) os << " (small)";
    first = false;
  }
  os << ". A tips-only calibration from these poses is ill-conditioned: "
        "calibrate from the images with `kincal bundle` (it also uses the "
        "tags' orientation), or record more poses spread over the joints' "
        "ranges that the cameras can see (`kincal plan --rig rig.yaml`).";
  return os.str();
}

}  // namespace kincal
