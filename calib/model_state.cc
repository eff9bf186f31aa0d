#include "calib/model_state.h"

#include <cmath>

#include "data/error.h"

namespace kincal {
namespace {
constexpr double kRadToDeg = 180.0 / M_PI;
const char* kJointErrorNames[kTransmission0] = {
    "gain",        "backlash",     "compliance",  "cyclic_cos",
    "cyclic_sin",  "cyclic2_cos",  "cyclic2_sin", "cyclic3_cos",
    "cyclic3_sin", "elastostatic", "thermal"};
// Entries past kTransmission0: "transmission1" .. "transmission24".
std::string JointErrorName(int index) {
  if (index < kTransmission0) return kJointErrorNames[index];
  return "transmission" + std::to_string(index - kTransmission0 + 1);
}
}  // namespace

int ModelState::PointIndex(const std::string& label) const {
  for (size_t i = 0; i < point_labels.size(); ++i) {
    if (point_labels[i] == label) return static_cast<int>(i);
  }
  return -1;
}

double ParamInfo::ToInterface(double internal) const {
  return angle ? internal * kRadToDeg : internal;
}

double ParamInfo::FromInterface(double value) const {
  return angle ? value / kRadToDeg : value;
}

std::string ParamInfo::InterfaceUnit() const {
  const std::string base = angle ? "deg" : "mm";
  if (kind == ParamKind::kDrift) {
    return index == kMountIso || index == kMountCos || index == kMountSin
               ? "deg/(N m)"
               : "mm/h";
  }
  if (kind != ParamKind::kJointError) return base;
  switch (index) {
    case kGain:
      return "1";
    case kThermal:
      return "1/K or 1/h";
    case kCompliance:
      return base + "/mm";
    case kElastostatic:
      return angle ? "deg/(N m)" : "mm/N";
    default:
      return base;
  }
}

double* ParamAddress(ModelState* s, const ParamInfo& p) {
  switch (p.kind) {
    case ParamKind::kRow:
      return &s->chain.rows.at(p.block).p.at(p.index);
    case ParamKind::kJointError:
      return &s->chain.joint_errors.at(p.block).at(p.index);
    case ParamKind::kDrift:
      return &s->chain.drift.at(p.index);
    case ParamKind::kFrame:
      return s->FrameBlock(p.block) + p.index;
    case ParamKind::kPoint:
      return &s->points_in_base.at(p.block).at(p.index);
  }
  return nullptr;
}

double ParamValue(const ModelState& state, const ParamInfo& p) {
  return *ParamAddress(const_cast<ModelState*>(&state), p);
}

std::vector<ParamInfo> GeometryParams(const Chain& chain) {
  std::vector<ParamInfo> out;
  for (int r = 0; r < static_cast<int>(chain.rows.size()); ++r) {
    const std::string& row = chain.rows[r].name;
    if (chain.convention == Convention::kUrdf) {
      const char* names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
      for (int k = 0; k < 6; ++k) {
        out.push_back({row + "." + names[k], ParamKind::kRow, r, k, k >= 3});
      }
    } else {
      out.push_back({row + ".theta", ParamKind::kRow, r, 0, true});
      out.push_back({row + ".d", ParamKind::kRow, r, 1, false});
      out.push_back({row + ".a", ParamKind::kRow, r, 2, false});
      out.push_back({row + ".alpha", ParamKind::kRow, r, 3, true});
    }
  }
  return out;
}

ParamInfo AxisTiltParam(const Chain& chain, int row) {
  KINCAL_CHECK(chain.convention != Convention::kUrdf,
               "beta applies to DH rows only");
  return {chain.rows.at(row).name + ".beta", ParamKind::kRow, row, 4, true};
}

std::vector<int> ParallelAxisRows(const Chain& chain) {
  std::vector<int> rows;
  if (chain.convention == Convention::kUrdf) return rows;
  for (int r = 0; r < chain.num_joints(); ++r) {
    if (std::abs(chain.rows[r].p[3]) < 1e-6) rows.push_back(r);
  }
  return rows;
}

std::vector<ParamInfo> FrameParams() {
  return {{"frame.rx", ParamKind::kFrame, 0, 0, true},
          {"frame.ry", ParamKind::kFrame, 0, 1, true},
          {"frame.rz", ParamKind::kFrame, 0, 2, true},
          {"frame.x", ParamKind::kFrame, 0, 3, false},
          {"frame.y", ParamKind::kFrame, 0, 4, false},
          {"frame.z", ParamKind::kFrame, 0, 5, false}};
}

std::vector<ParamInfo> AllFrameParams(const ModelState& state) {
  if (state.NumFrames() == 1) return FrameParams();
  std::vector<ParamInfo> out;
  for (int f = 0; f < state.NumFrames(); ++f) {
    std::string label = f < static_cast<int>(state.frame_series.size())
                            ? state.frame_series[f]
                            : std::to_string(f);
    if (label.empty()) label = "unlabelled";
    for (ParamInfo p : FrameParams()) {
      p.name = "frame." + label + p.name.substr(5);
      p.block = f;
      out.push_back(p);
    }
  }
  return out;
}

std::vector<ParamInfo> PointParams(const ModelState& state) {
  std::vector<ParamInfo> out;
  for (int i = 0; i < static_cast<int>(state.point_labels.size()); ++i) {
    const std::string base = "point." + state.point_labels[i] + ".";
    out.push_back({base + "x", ParamKind::kPoint, i, 0, false});
    out.push_back({base + "y", ParamKind::kPoint, i, 1, false});
    out.push_back({base + "z", ParamKind::kPoint, i, 2, false});
  }
  return out;
}

ParamInfo JointErrorParam(const Chain& chain, int joint, int index) {
  // Revolute: backlash and cyclic terms are angles, compliance is an angle
  // per mm of torque; all shown in degrees. Gain is dimensionless.
  const bool angle = chain.rows.at(joint).type == JointType::kRevolute &&
                     index != kGain && index != kThermal;
  return {chain.rows[joint].name + "." + JointErrorName(index),
          ParamKind::kJointError, joint, index, angle};
}

std::vector<ParamInfo> DriftParams() {
  return {{"drift.vx", ParamKind::kDrift, 0, 0, false},
          {"drift.vy", ParamKind::kDrift, 0, 1, false},
          {"drift.vz", ParamKind::kDrift, 0, 2, false}};
}

std::vector<ParamInfo> MountParams() {
  return {{"mount.iso", ParamKind::kDrift, 0, kMountIso, true},
          {"mount.aniso_cos", ParamKind::kDrift, 0, kMountCos, true},
          {"mount.aniso_sin", ParamKind::kDrift, 0, kMountSin, true}};
}

ParamInfo FindParam(const ModelState& state, const std::string& name) {
  std::vector<ParamInfo> all = GeometryParams(state.chain);
  for (const auto& p : AllFrameParams(state)) all.push_back(p);
  for (const auto& p : PointParams(state)) all.push_back(p);
  for (const auto& p : DriftParams()) all.push_back(p);
  for (const auto& p : MountParams()) all.push_back(p);
  for (int j = 0; j < state.chain.num_joints(); ++j) {
    for (int k = 0; k < kJointErrorBlockSize; ++k) {
      all.push_back(JointErrorParam(state.chain, j, k));
    }
  }
  // Every DH / MDH row carries a beta (a calibrated row's alpha is no longer
  // exactly 0, so not only the nominally parallel ones).
  if (state.chain.convention != Convention::kUrdf) {
    for (int r = 0; r < state.chain.num_joints(); ++r) {
      all.push_back(AxisTiltParam(state.chain, r));
    }
  }
  for (const auto& p : all) {
    if (p.name == name) return p;
  }
  throw InputError("unknown parameter '" + name +
                   "' (names are <row>.<field>, e.g. j3.a, tool.d, frame.x)");
}

}  // namespace kincal
