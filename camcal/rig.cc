#include "camcal/rig.h"

#include <Eigen/SVD>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/yaml_util.h"

namespace kincal {

double Rig::BaselineMm() const {
  if (cameras.size() < 2) return 0.0;
  // Camera centre in rig = -R^T t.
  const Eigen::Vector3d c0 = cameras[0].cam_from_rig.Inverse().t;
  const Eigen::Vector3d c1 = cameras[1].cam_from_rig.Inverse().t;
  return (c1 - c0).norm();
}

const char* RigMountName(RigMount mount) {
  return mount == RigMount::kFlange ? "flange" : "world";
}

std::vector<std::string> Rig::CameraNames() const {
  std::vector<std::string> names;
  for (const Camera& c : cameras) names.push_back(c.intrinsics.name);
  return names;
}

int Rig::FindCamera(const std::string& name) const {
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (cameras[c].intrinsics.name == name) return static_cast<int>(c);
  }
  return -1;
}

namespace {

Rigid3 ParsePose(const YamlReader& y, const YAML::Node& node,
                 const std::string& what) {
  y.ExpectMap(node, what);
  y.CheckKeys(node, {"R", "t"}, what);
  const YAML::Node r_node = y.Required(node, "R", what);
  const std::vector<double> r = y.Numbers(r_node, what + ".R", 9, 9);
  const std::vector<double> t =
      y.Numbers(y.Required(node, "t", what), what + ".t", 3, 3);
  Rigid3 pose;
  pose.R =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data());
  pose.t = Eigen::Vector3d(t[0], t[1], t[2]);
  // Physical range: cameras of one rig within 100 m of each other.
  if (!(pose.t.cwiseAbs().maxCoeff() <= 1e5)) {
    y.Fail(node["t"], what + ".t: expected each coordinate within +-1e5 mm");
  }
  const double ortho =
      (pose.R.transpose() * pose.R - Eigen::Matrix3d::Identity()).norm();
  if (ortho > 1e-4 || pose.R.determinant() <= 0) {
    std::ostringstream os;
    os << what << ".R: expected a rotation matrix (orthonormal, det +1), got "
       << "|R^T R - I| = " << ortho << ", det = " << pose.R.determinant();
    y.Fail(r_node, os.str());
  }
  // Nearest rotation (removes rounding of hand-typed values).
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      pose.R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  pose.R = svd.matrixU() * svd.matrixV().transpose();
  return pose;
}

// [[u, v], ...] in px.
std::vector<Eigen::Vector2d> ParseRegion(const YamlReader& y,
                                         const YAML::Node& node,
                                         const std::string& what) {
  y.ExpectSequence(node, what);
  std::vector<Eigen::Vector2d> region;
  for (size_t k = 0; k < node.size(); ++k) {
    const std::vector<double> uv = y.Numbers(node[k], what, 2, 2);
    if (!(std::abs(uv[0]) <= 1e6 && std::abs(uv[1]) <= 1e6)) {
      y.Fail(node[k], what + ": expected pixels within +-1e6");
    }
    region.emplace_back(uv[0], uv[1]);
  }
  return region;
}

std::string Join(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) {
    s += (i ? ", " : "") + FormatDouble(v[i]);
  }
  return s + "]";
}

// A YAML scalar for a camera name: plain when safe, else double-quoted.
std::string YamlName(const std::string& name) {
  bool plain = !name.empty();
  for (char c : name) {
    plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
                      c == '-' || c == '.');
  }
  if (plain && !std::isdigit(static_cast<unsigned char>(name[0]))) return name;
  std::string q = "\"";
  for (char c : name) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

}  // namespace

Rig ParseRigYaml(const std::string& text, const std::string& file) {
  const YamlReader y(file);
  const YAML::Node root = y.Load(text);
  if (!root.IsDefined() || root.IsNull()) {
    throw InputError(file, 0, 0, "empty file: expected a kincal_rig document");
  }
  y.ExpectMap(root, "rig file");
  y.CheckKeys(root, {"kincal_rig", "mount", "cameras"}, "rig file");
  const YAML::Node version = y.Required(root, "kincal_rig", "rig file");
  if (y.Integer(version, "kincal_rig") != 1) {
    y.Fail(version,
           "kincal_rig: expected format version 1, got " + version.Scalar());
  }
  const YAML::Node cams = y.Required(root, "cameras", "rig file");
  y.ExpectSequence(cams, "cameras");
  if (cams.size() == 0) y.Fail(cams, "cameras: expected at least one camera");

  Rig rig;
  if (root["mount"]) {
    const std::string mount = y.String(root["mount"], "mount");
    if (mount == "flange") {
      rig.mount = RigMount::kFlange;
    } else if (mount != "world") {
      y.Fail(root["mount"],
             "mount: expected world (cameras on a stand, target on the "
             "flange) or flange (cameras on the flange, target fixed), got '" +
                 mount + "'");
    }
  }
  std::set<std::string> names;
  for (size_t i = 0; i < cams.size(); ++i) {
    const YAML::Node c = cams[i];
    const std::string what = "cameras[" + std::to_string(i) + "]";
    y.ExpectMap(c, what);
    y.CheckKeys(c,
                {"name", "width", "height", "fx", "fy", "cx", "cy",
                 "distortion", "cam_from_rig", "valid_intrinsics_region"},
                what);
    Camera cam;
    CameraIntrinsics& in = cam.intrinsics;
    const YAML::Node name = y.Required(c, "name", what);
    in.name = y.String(name, what + ".name");
    if (!names.insert(in.name).second) {
      y.Fail(name, what + ".name: duplicate camera name '" + in.name + "'");
    }
    auto positive_int = [&](const char* key) {
      const YAML::Node n = y.Required(c, key, what);
      const int v = y.Integer(n, what + "." + key);
      if (v <= 0 || v > 100000) {
        y.Fail(n, what + "." + key +
                      ": expected a positive integer size in px, up to 100000");
      }
      return v;
    };
    in.width = positive_int("width");
    in.height = positive_int("height");
    auto number = [&](const char* key, bool positive) {
      const YAML::Node n = y.Required(c, key, what);
      const double v = y.Number(n, what + "." + key);
      if (positive && !(v >= 1 && v <= 1e6)) {
        y.Fail(n, what + "." + key +
                      ": expected a positive focal length in px, 1 to 1e6");
      }
      if (!positive && !(std::abs(v) <= 1e6)) {
        y.Fail(n,
               what + "." + key + ": expected a position in px within +-1e6");
      }
      return v;
    };
    in.fx = number("fx", true);
    in.fy = number("fy", true);
    in.cx = number("cx", false);
    in.cy = number("cy", false);
    const YAML::Node dist = y.Required(c, "distortion", what);
    in.distortion = y.Numbers(dist, what + ".distortion", 0, 8);
    const size_t nd = in.distortion.size();
    for (double k : in.distortion) {
      if (!(std::abs(k) <= 1e4)) {
        y.Fail(dist, what + ".distortion: expected coefficients within +-1e4");
      }
    }
    if (nd != 0 && nd != 4 && nd != 5 && nd != 8) {
      y.Fail(dist, what +
                       ".distortion: expected 0, 4, 5 or 8 numbers (OpenCV "
                       "k1, k2, p1, p2[, k3[, k4, k5, k6]]), got " +
                       std::to_string(nd));
    }
    const YAML::Node pose = y.Required(c, "cam_from_rig", what);
    cam.cam_from_rig = ParsePose(y, pose, what + ".cam_from_rig");
    if (i == 0 &&
        ((cam.cam_from_rig.R - Eigen::Matrix3d::Identity()).norm() > 1e-9 ||
         cam.cam_from_rig.t.norm() > 1e-9)) {
      y.Fail(pose, what +
                       ".cam_from_rig: the first camera defines the rig frame; "
                       "expected R = identity, t = [0, 0, 0]");
    }
    if (i == 0) cam.cam_from_rig = Rigid3();
    if (c["valid_intrinsics_region"]) {
      cam.valid_intrinsics_region = ParseRegion(
          y, c["valid_intrinsics_region"], what + ".valid_intrinsics_region");
    }
    rig.cameras.push_back(std::move(cam));
  }
  return rig;
}

Rig ReadRigYaml(const std::string& path) {
  return ParseRigYaml(ReadFile(path), path);
}

std::string RigToYaml(const Rig& rig) {
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  os << "kincal_rig: 1\n";
  if (rig.mount == RigMount::kFlange) {
    os << "mount: flange  # cameras on the robot's flange, target fixed\n";
  }
  os << "cameras:  # the first camera is the reference; rig frame = its "
        "frame\n";
  for (const Camera& cam : rig.cameras) {
    const CameraIntrinsics& in = cam.intrinsics;
    os << "  - name: " << YamlName(in.name) << "\n";
    os << "    width: " << in.width << "\n";
    os << "    height: " << in.height << "\n";
    os << "    fx: " << FormatDouble(in.fx) << "\n";
    os << "    fy: " << FormatDouble(in.fy) << "\n";
    os << "    cx: " << FormatDouble(in.cx) << "\n";
    os << "    cy: " << FormatDouble(in.cy) << "\n";
    os << "    distortion: " << Join(in.distortion) << "\n";
    const Eigen::Matrix3d& R = cam.cam_from_rig.R;
    std::vector<double> r;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) r.push_back(R(row, col));
    }
    const Eigen::Vector3d& t = cam.cam_from_rig.t;
    os << "    cam_from_rig: {R: " << Join(r)
       << ", t: " << Join({t.x(), t.y(), t.z()}) << "}  # R row-major, t mm\n";
    if (!cam.valid_intrinsics_region.empty()) {
      os << "    valid_intrinsics_region: [";
      for (size_t k = 0; k < cam.valid_intrinsics_region.size(); ++k) {
        const Eigen::Vector2d& p = cam.valid_intrinsics_region[k];
        os << (k ? ", " : "") << Join({p.x(), p.y()});
      }
      os << "]  # px, projection uncertainty below the threshold\n";
    }
  }
  return os.str();
}

void WriteRigYaml(const std::string& path, const Rig& rig) {
  WriteFileAtomic(path, RigToYaml(rig));
}

}  // namespace kincal
