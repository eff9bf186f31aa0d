#include "vision/target.h"

#include <Eigen/Dense>
#include <set>
#include <sstream>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/yaml_util.h"
#include "vision/apriltag_detector.h"

namespace kincal {

Eigen::Vector3d TargetTag::CornerInTool(int k) const {
  return tool_from_tag * TagCornerInTag(k, size_mm);
}

const TargetTag* Target::FindTag(int id) const {
  for (const auto& t : tags) {
    if (t.id == id) return &t;
  }
  return nullptr;
}

namespace {

// Physical ranges of a target file (mm).
constexpr double kMaxToolMm = 1e4;
constexpr double kMinTagMm = 0.5, kMaxTagMm = 5000.0;

Rigid3 ReadPose(const YamlReader& r, const YAML::Node& node,
                const std::string& what) {
  r.ExpectMap(node, what);
  r.CheckKeys(node, {"R", "t"}, what);
  const auto R = r.Numbers(r.Required(node, "R", what), what + ".R", 9, 9);
  const auto t = r.Numbers(r.Required(node, "t", what), what + ".t", 3, 3);
  Rigid3 pose;
  pose.R << R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8];
  pose.t = Eigen::Vector3d(t[0], t[1], t[2]);
  // Physical range: a tag on a tool sits within a metre of the tool origin
  // (10 m allowed); beyond that the solver's arithmetic loses the tag.
  if (!(pose.t.cwiseAbs().maxCoeff() <= kMaxToolMm)) {
    r.Fail(node["t"], what + ".t: expected each coordinate within +-" +
                          FormatDouble(kMaxToolMm) + " mm of the tool origin");
  }
  const double err =
      (pose.R.transpose() * pose.R - Eigen::Matrix3d::Identity()).norm();
  if (err > 1e-3 || pose.R.determinant() <= 0) {
    std::ostringstream os;
    os << what << ".R: expected a rotation matrix (orthonormal, det +1), got "
       << "|R^T R - I| = " << err << ", det = " << pose.R.determinant();
    r.Fail(node["R"], os.str());
  }
  // Nearest rotation (rounded input).
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      pose.R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  pose.R = svd.matrixU() * svd.matrixV().transpose();
  return pose;
}

// A list of three non-negative numbers (a sigma), e.g. tip_sigma_mm.
Eigen::Vector3d ReadSigma(const YamlReader& r, const YAML::Node& node,
                          const std::string& what) {
  const auto v = r.Numbers(node, what, 3, 3);
  for (double x : v) {
    if (!(x >= 0 && x < kMaxToolMm)) {
      r.Fail(node, what + ": expected three non-negative numbers (1-sigma)");
    }
  }
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

std::string Vec(const Eigen::Vector3d& v) {
  return "[" + FormatDouble(v.x()) + ", " + FormatDouble(v.y()) + ", " +
         FormatDouble(v.z()) + "]";
}

}  // namespace

Target ParseTargetYaml(const std::string& text, const std::string& file) {
  YamlReader r(file);
  const YAML::Node root = r.Load(text);
  if (!root.IsDefined() || root.IsNull()) {
    throw InputError(file, 0, 0, "empty file: expected a tool target");
  }
  r.ExpectMap(root, "target file");
  r.CheckKeys(root,
              {"kincal_target", "family", "tags", "tip_in_tool", "tip_sigma_mm",
               "made_by"},
              "target file");
  const YAML::Node version = r.Required(root, "kincal_target", "target file");
  if (r.Integer(version, "kincal_target") != 1) {
    r.Fail(version, "kincal_target: unsupported format version " +
                        version.Scalar() + " (this tool reads version 1)");
  }
  Target target;
  if (root["family"]) {
    target.family = r.String(root["family"], "family");
    if (!IsKnownTagFamily(target.family)) {
      r.Fail(root["family"], "family: unknown tag family '" + target.family +
                                 "' (expected tag36h11, tag25h9 or tag16h5)");
    }
  }
  const int family_size = TagFamilySize(target.family);
  const YAML::Node tags = r.Required(root, "tags", "target file");
  r.ExpectSequence(tags, "tags");
  if (tags.size() == 0) r.Fail(tags, "tags: expected at least one tag");
  std::set<int> ids;
  for (size_t i = 0; i < tags.size(); ++i) {
    const YAML::Node t = tags[i];
    const std::string what = "tags[" + std::to_string(i) + "]";
    r.ExpectMap(t, what);
    r.CheckKeys(t, {"id", "size", "tool_from_tag", "sigma"}, what);
    TargetTag tag;
    const YAML::Node id = r.Required(t, "id", what);
    tag.id = r.Integer(id, what + ".id");
    if (tag.id < 0 || tag.id >= family_size) {
      r.Fail(id, what + ".id: " + std::to_string(tag.id) + " is not in " +
                     target.family + " (0.." + std::to_string(family_size - 1) +
                     ")");
    }
    if (!ids.insert(tag.id).second) {
      r.Fail(id, what + ".id: duplicate tag id " + std::to_string(tag.id));
    }
    const YAML::Node size = r.Required(t, "size", what);
    tag.size_mm = r.Number(size, what + ".size");
    if (!(tag.size_mm >= kMinTagMm && tag.size_mm <= kMaxTagMm)) {
      const bool metres = tag.size_mm > 0 && tag.size_mm < kMinTagMm;
      r.Fail(size,
             what + ".size: expected a positive edge length in mm between " +
                 FormatDouble(kMinTagMm) + " and " + FormatDouble(kMaxTagMm) +
                 (metres ? ", got " + FormatDouble(tag.size_mm) +
                               ": a size in metres? target.yaml lengths are "
                               "millimetres (multiply by 1000)"
                         : std::string()));
    }
    tag.tool_from_tag = ReadPose(r, r.Required(t, "tool_from_tag", what),
                                 what + ".tool_from_tag");
    if (t["sigma"]) {
      const YAML::Node sigma = t["sigma"];
      const std::string sw = what + ".sigma";
      r.ExpectMap(sigma, sw);
      r.CheckKeys(sigma, {"t_mm", "r_deg"}, sw);
      tag.has_sigma = true;
      tag.sigma_t_mm =
          ReadSigma(r, r.Required(sigma, "t_mm", sw), sw + ".t_mm");
      tag.sigma_r_deg =
          ReadSigma(r, r.Required(sigma, "r_deg", sw), sw + ".r_deg");
    }
    target.tags.push_back(tag);
  }
  target.has_tip = static_cast<bool>(root["tip_in_tool"]);
  if (target.has_tip) {
    const auto tip = r.Numbers(root["tip_in_tool"], "tip_in_tool", 3, 3);
    target.tip_in_tool = Eigen::Vector3d(tip[0], tip[1], tip[2]);
    if (!(target.tip_in_tool.cwiseAbs().maxCoeff() <= kMaxToolMm)) {
      r.Fail(root["tip_in_tool"],
             "tip_in_tool: expected each coordinate within +-" +
                 FormatDouble(kMaxToolMm) + " mm of the tool origin");
    }
  }
  if (root["tip_sigma_mm"]) {
    target.has_tip_sigma = true;
    target.tip_sigma_mm = ReadSigma(r, root["tip_sigma_mm"], "tip_sigma_mm");
  }
  if (root["made_by"]) target.made_by = r.String(root["made_by"], "made_by");
  return target;
}

Target ReadTargetYaml(const std::string& path) {
  return ParseTargetYaml(ReadFile(path), path);
}

std::string FormatTargetYaml(const Target& target) {
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  os << "kincal_target: 1\n";
  os << "family: " << target.family << "\n";
  os << "tags:  # size = edge of the black square, mm; R row-major\n";
  for (const auto& t : target.tags) {
    const Eigen::Matrix3d& R = t.tool_from_tag.R;
    os << "  - {id: " << t.id << ", size: " << FormatDouble(t.size_mm)
       << ", tool_from_tag: {R: [";
    for (int i = 0; i < 9; ++i) {
      os << (i ? ", " : "") << FormatDouble(R(i / 3, i % 3));
    }
    os << "], t: " << Vec(t.tool_from_tag.t) << "}";
    if (t.has_sigma) {
      os << ", sigma: {t_mm: " << Vec(t.sigma_t_mm)
         << ", r_deg: " << Vec(t.sigma_r_deg) << "}";
    }
    os << "}\n";
  }
  if (target.has_tip) {
    os << "tip_in_tool: " << Vec(target.tip_in_tool) << "\n";
  }
  if (target.has_tip_sigma) {
    os << "tip_sigma_mm: " << Vec(target.tip_sigma_mm) << "\n";
  }
  if (!target.made_by.empty()) {
    YAML::Emitter quoted;
    quoted << YAML::DoubleQuoted << target.made_by;
    os << "made_by: " << quoted.c_str() << "\n";
  }
  return os.str();
}

void WriteTargetYaml(const std::string& path, const Target& target) {
  WriteFileAtomic(path, FormatTargetYaml(target));
}

Rigid3 TipFromTool(const Target& target) {
  Rigid3 tip_from_tool;
  tip_from_tool.R << 0, 0, 1,  //
      1, 0, 0,                 //
      0, 1, 0;
  tip_from_tool.t = -(tip_from_tool.R * target.tip_in_tool);
  return tip_from_tool;
}

}  // namespace kincal
