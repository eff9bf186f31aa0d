#include "diagnose/iso9283.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "calib/chain.h"
#include "calib/evaluate.h"
#include "calib/fit.h"
#include "data/error.h"

namespace kincal {
namespace {

// The labelled rows grouped by label, labels in order of first visit.
struct LabelGroups {
  std::vector<std::string> labels;
  std::vector<std::vector<int>> rows;
  int unlabelled = 0;
};

LabelGroups GroupByLabel(const Observations& obs) {
  LabelGroups g;
  std::map<std::string, int> index;
  for (size_t i = 0; i < obs.rows.size(); ++i) {
    const Observation& o = obs.rows[i];
    if (o.fixed_point.empty()) {
      ++g.unlabelled;
      continue;
    }
    if (!o.has_point) {
      throw InputError(obs.source, o.line, 1,
                       "row of pose '" + o.pose + "' is labelled '" +
                           o.fixed_point +
                           "' but has no measured x,y,z: every cycle of a "
                           "commanded pose needs its attained position");
    }
    auto it = index.find(o.fixed_point);
    if (it == index.end()) {
      it =
          index.emplace(o.fixed_point, static_cast<int>(g.labels.size())).first;
      g.labels.push_back(o.fixed_point);
      g.rows.emplace_back();
    }
    g.rows[it->second].push_back(static_cast<int>(i));
  }
  if (g.labels.empty()) {
    throw InputError(obs.source, 0, 0,
                     "no row has a fixed_point label: ISO 9283 needs the "
                     "label of the commanded pose (P1..P5) on every measured "
                     "cycle");
  }
  for (size_t k = 0; k < g.labels.size(); ++k) {
    if (g.rows[k].size() < 2) {
      const Observation& o = obs.rows[g.rows[k][0]];
      throw InputError(obs.source, o.line, 1,
                       "pose '" + g.labels[k] +
                           "' is visited once: repeatability needs n >= 2 "
                           "cycles per pose (the standard asks for 30)");
    }
  }
  return g;
}

// The rigid fit of the model's tips to the measured points of `rows`
// (Umeyama, calib/fit.h), and its residual RMS.
Rigid3 RegisterOnRows(const Chain& chain, const Observations& obs,
                      const std::vector<PoseInput>& inputs,
                      const std::vector<int>& rows, double* rms_mm) {
  std::vector<Measurement> ms;
  for (int i : rows) {
    Measurement m;
    m.row = i;
    m.kind = Measurement::kMeasured;
    m.input = inputs[i];
    m.p_in_meas = obs.rows[i].p_in_meas;
    ms.push_back(m);
  }
  ModelState state;
  state.chain = chain;
  InitializeFrameAndPoints(ms, &state);
  double sum = 0.0;
  for (const Measurement& m : ms) sum += Residual(state, m).squaredNorm();
  *rms_mm = std::sqrt(sum / ms.size());
  return Rigid3FromPoseBlock(state.meas_from_base.data());
}

// One pose's characteristics from its rows: the commanded position is the
// mean of the model's tips at the rows' readings, the attained ones the
// measured points in the base frame.
Iso9283Pose EvaluatePose(const Chain& chain, const Observations& obs,
                         const std::vector<PoseInput>& inputs,
                         const std::vector<int>& rows,
                         const Rigid3& base_from_meas) {
  std::vector<Eigen::Vector3d> tips, attained;
  Eigen::Vector3d commanded = Eigen::Vector3d::Zero();
  for (int i : rows) {
    tips.push_back(TipInBase(chain, inputs[i]));
    commanded += tips.back();
    attained.push_back(base_from_meas * obs.rows[i].p_in_meas);
  }
  commanded /= static_cast<double>(tips.size());
  Iso9283Pose p = PoseCharacteristics(commanded, attained);
  p.rows = rows;
  for (const Eigen::Vector3d& t : tips) {
    p.commanded_spread_mm =
        std::max(p.commanded_spread_mm, (t - commanded).norm());
  }
  return p;
}

}  // namespace

Iso9283Pose PoseCharacteristics(const Eigen::Vector3d& commanded_mm,
                                const std::vector<Eigen::Vector3d>& attained) {
  Require(!attained.empty(), "ISO 9283: a pose without attained positions");
  Iso9283Pose p;
  p.n = static_cast<int>(attained.size());
  p.commanded_mm = commanded_mm;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : attained) sum += x;
  p.barycentre_mm = sum / p.n;
  p.ap_xyz_mm = p.barycentre_mm - commanded_mm;
  p.ap_mm = p.ap_xyz_mm.norm();
  std::vector<double> l;
  for (const Eigen::Vector3d& x : attained) {
    l.push_back((x - p.barycentre_mm).norm());
  }
  double l_sum = 0.0;
  for (double v : l) l_sum += v;
  p.l_mean_mm = l_sum / p.n;
  double sq = 0.0;
  for (double v : l) sq += (v - p.l_mean_mm) * (v - p.l_mean_mm);
  p.s_l_mm = p.n > 1 ? std::sqrt(sq / (p.n - 1)) : 0.0;
  p.rp_mm = p.l_mean_mm + 3.0 * p.s_l_mm;
  return p;
}

Iso9283Result ComputeIso9283(const Robot& robot, const Observations& obs,
                             const Iso9283Options& options) {
  const LabelGroups groups = GroupByLabel(obs);
  const Chain chain = Chain::FromRobot(robot);
  // Every row, labelled or not, gives the approach directions.
  const std::vector<PoseInput> inputs = MakePoseInputs(chain, obs);
  Iso9283Result r;
  r.unlabelled_rows = groups.unlabelled;
  if (options.meas_from_base) {
    r.meas_from_base = *options.meas_from_base;
    r.frame_registered_on_poses = false;
    r.registration_rms_mm = options.given_frame_rms_mm;
    r.registration_rows = options.given_frame_rows;
  } else {
    std::vector<int> all;
    for (const auto& rows : groups.rows) {
      all.insert(all.end(), rows.begin(), rows.end());
    }
    std::sort(all.begin(), all.end());
    r.meas_from_base =
        RegisterOnRows(chain, obs, inputs, all, &r.registration_rms_mm);
    r.registration_rows = static_cast<int>(all.size());
  }
  const Rigid3 base_from_meas = r.meas_from_base.Inverse();
  r.tolerance_given =
      options.ap_tolerance_mm > 0 || options.rp_tolerance_mm > 0;
  for (size_t k = 0; k < groups.labels.size(); ++k) {
    Iso9283Pose p =
        EvaluatePose(chain, obs, inputs, groups.rows[k], base_from_meas);
    p.label = groups.labels[k];
    if (options.ap_tolerance_mm > 0 && !(p.ap_mm <= options.ap_tolerance_mm))
      p.pass = false;
    if (options.rp_tolerance_mm > 0 && !(p.rp_mm <= options.rp_tolerance_mm))
      p.pass = false;
    r.pass = r.pass && p.pass;
    r.ap_max_mm = std::max(r.ap_max_mm, p.ap_mm);
    r.rp_max_mm = std::max(r.rp_max_mm, p.rp_mm);
    r.poses.push_back(p);
  }
  return r;
}

Iso9283Options RegisterMeasuringFrame(const Robot& robot,
                                      const Observations& obs,
                                      Iso9283Options options) {
  ModelState start;
  start.chain = Chain::FromRobot(robot);
  const std::vector<Measurement> ms =
      MakeMeasurements(start.chain, obs, &start);
  if (ms.empty()) {
    throw InputError(obs.source, 0, 0,
                     "no row has a measured tip (x, y, z): nothing to "
                     "register the measuring frame on");
  }
  const Registration reg = Register(start, ms, std::vector<char>(ms.size(), 0));
  options.meas_from_base = Rigid3FromPoseBlock(reg.state.meas_from_base.data());
  options.given_frame_rms_mm = reg.stats.rms_mm;
  options.given_frame_rows = reg.stats.n;
  return options;
}

namespace {

nlohmann::json Num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json Vec(const Eigen::Vector3d& v) {
  return {Num(v.x()), Num(v.y()), Num(v.z())};
}

}  // namespace

nlohmann::json Iso9283Json(const Iso9283Result& r) {
  nlohmann::json poses = nlohmann::json::array();
  for (const Iso9283Pose& p : r.poses) {
    nlohmann::json j = {{"pose", p.label},
                        {"n", p.n},
                        {"ap_mm", Num(p.ap_mm)},
                        {"rp_mm", Num(p.rp_mm)},
                        {"ap_x_mm", Num(p.ap_xyz_mm.x())},
                        {"ap_y_mm", Num(p.ap_xyz_mm.y())},
                        {"ap_z_mm", Num(p.ap_xyz_mm.z())},
                        {"barycentre_mm", Vec(p.barycentre_mm)},
                        {"commanded_mm", Vec(p.commanded_mm)},
                        {"commanded_spread_mm", Num(p.commanded_spread_mm)},
                        {"l_mean_mm", Num(p.l_mean_mm)},
                        {"s_l_mm", Num(p.s_l_mm)}};
    if (r.tolerance_given) j["pass"] = p.pass;
    poses.push_back(j);
  }
  const Eigen::Vector3d w = RotationVectorFromMatrix(r.meas_from_base.R);
  nlohmann::json out = {
      {"poses", poses},
      {"ap_max_mm", Num(r.ap_max_mm)},
      {"rp_max_mm", Num(r.rp_max_mm)},
      {"frame", r.frame_registered_on_poses ? "registered_on_poses" : "given"},
      {"registration_rms_mm", Num(r.registration_rms_mm)},
      {"registration_rows", r.registration_rows},
      {"meas_from_base",
       {{"rotation_vector_deg", Vec(w * 180.0 / M_PI)},
        {"translation_mm", Vec(r.meas_from_base.t)}}},
      {"unlabelled_rows", r.unlabelled_rows},
      {"orientation",
       "not computed: observations carry positions only (AP_a, RP_a need "
       "measured orientations)"}};
  if (r.tolerance_given) out["pass"] = r.pass;
  return out;
}

std::string Iso9283Text(const Iso9283Result& r, const std::string& indent) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof(line),
                "%s%-8s %4s %9s %9s %9s %9s %9s %9s %9s%s\n", indent.c_str(),
                "pose", "n", "AP_mm", "AP_x", "AP_y", "AP_z", "l_mean", "S_l",
                "RP_mm", r.tolerance_given ? "  pass" : "");
  out += line;
  for (const Iso9283Pose& p : r.poses) {
    std::snprintf(line, sizeof(line),
                  "%s%-8s %4d %9.4f %9.4f %9.4f %9.4f %9.4f %9.4f %9.4f%s\n",
                  indent.c_str(), p.label.c_str(), p.n, p.ap_mm,
                  p.ap_xyz_mm.x(), p.ap_xyz_mm.y(), p.ap_xyz_mm.z(),
                  p.l_mean_mm, p.s_l_mm, p.rp_mm,
                  !r.tolerance_given ? ""
                  : p.pass           ? "  yes"
                                     : "  NO");
    out += line;
  }
  std::snprintf(line, sizeof(line), "%smax AP %.4f mm, max RP %.4f mm%s\n",
                indent.c_str(), r.ap_max_mm, r.rp_max_mm,
                !r.tolerance_given ? ""
                : r.pass           ? ": PASS"
                                   : ": FAIL");
  out += line;
  return out;
}

bool HasIso9283Rows(const Observations& obs) {
  for (const Observation& o : obs.rows) {
    if (!o.fixed_point.empty() && o.has_point) return true;
  }
  return false;
}

}  // namespace kincal
