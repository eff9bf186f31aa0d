#include "calib/urdf_export.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

#include "calib/chain.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/svg_plot.h"

namespace kincal {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

std::string Num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.17g", v == 0.0 ? 0.0 : v);
  return buf;
}

std::string Short(double v) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

// XML forbids "--" inside a comment (and a trailing '-'): written "- -".
std::string CommentText(std::string s) {
  for (size_t at = s.find("--"); at != std::string::npos; at = s.find("--")) {
    s.replace(at, 2, "- -");
  }
  if (!s.empty() && s.back() == '-') s += ' ';
  return s;
}

std::string Origin(const Eigen::Matrix4d& m_mm) {
  const Eigen::Vector3d rpy = MatrixToRpy(m_mm.block<3, 3>(0, 0));
  const Eigen::Vector3d t = m_mm.block<3, 1>(0, 3) / 1000.0;
  return "<origin xyz=\"" + Num(t.x()) + " " + Num(t.y()) + " " + Num(t.z()) +
         "\" rpy=\"" + Num(rpy.x()) + " " + Num(rpy.y()) + " " + Num(rpy.z()) +
         "\"/>";
}

Eigen::Matrix4d RowAtZero(const Chain& chain, int i) {
  return RowTransform<double>(chain.convention, chain.rows[i],
                              chain.rows[i].p.data(), 0.0);
}

}  // namespace

Eigen::Vector3d MatrixToRpy(const Eigen::Matrix3d& r) {
  const double c = std::hypot(r(0, 0), r(1, 0));
  const double pitch = std::atan2(-r(2, 0), c);
  if (c < 1e-10) {
    return Eigen::Vector3d(0.0, pitch, std::atan2(-r(0, 1), r(1, 1)));
  }
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)), pitch,
                         std::atan2(r(1, 0), r(0, 0)));
}

std::string DescribeExtension(const Extension& e) {
  std::string s = e.cause + (e.joint.empty() ? "" : " " + e.joint) + ":";
  for (const auto& [k, v] : e.values) s += " " + k + "=" + Short(v);
  return s;
}

UrdfExport ExportUrdf(const Robot& robot) {
  const Chain chain = Chain::FromRobot(robot);
  const int n = chain.num_joints();
  UrdfExport out;
  for (const Extension& e : robot.extensions) {
    out.not_exported.push_back(DescribeExtension(e));
  }

  // Joint k's origin (frame of its parent link -> frame before its motion)
  // and the tool's origin, by convention (see the header).
  std::vector<Eigen::Matrix4d> origin(n);
  Eigen::Matrix4d tool = RowAtZero(chain, chain.tool_row());
  for (int k = 0; k < n; ++k) {
    if (chain.convention == Convention::kDh) {
      origin[k] =
          k == 0 ? Eigen::Matrix4d::Identity() : RowAtZero(chain, k - 1);
    } else {
      origin[k] = RowAtZero(chain, k);
    }
  }
  if (chain.convention == Convention::kDh && n > 0) {
    tool = RowAtZero(chain, n - 1) * tool;
  }

  std::ostringstream joints;
  auto link_name = [&](int k) {
    return k < 0 ? std::string("base_link") : robot.joints[k].name + "_link";
  };
  for (int k = 0; k < n; ++k) {
    const RobotRow& row = robot.joints[k];
    const bool prismatic = row.type == JointType::kPrismatic;
    std::string type = prismatic ? "prismatic" : "revolute";
    if (!prismatic && !row.HasLimits()) type = "continuous";
    const Eigen::Vector3d axis = chain.convention == Convention::kUrdf
                                     ? chain.rows[k].axis
                                     : Eigen::Vector3d::UnitZ();
    joints << "  <joint name=\"" << XmlEscape(row.name) << "\" type=\"" << type
           << "\">\n    <parent link=\"" << XmlEscape(link_name(k - 1))
           << "\"/>\n    <child link=\"" << XmlEscape(link_name(k))
           << "\"/>\n    " << Origin(origin[k]) << "\n    <axis xyz=\""
           << Num(axis.x()) << " " << Num(axis.y()) << " " << Num(axis.z())
           << "\"/>\n";
    if (type != "continuous") {
      double lo = -1.0, hi = 1.0;  // m: placeholder for a prismatic joint
      if (row.HasLimits()) {
        const double scale = prismatic ? 1e-3 : 1.0 / kRadToDeg;
        lo = row.lower * scale;
        hi = row.upper * scale;
      } else {
        out.placeholders.push_back(
            row.name + ": no limits in the robot file; URDF limit [-1, 1] m");
      }
      joints << "    <limit lower=\"" << Num(lo) << "\" upper=\"" << Num(hi)
             << "\" effort=\"0\" velocity=\"0\"/>\n";
    }
    joints << "  </joint>\n";
  }
  if (n > 0 && !out.placeholders.empty()) {
    out.placeholders.push_back(
        "effort and velocity limits are 0 (the robot file has none)");
  } else if (n > 0) {
    bool any_limit = false;
    for (const RobotRow& r : robot.joints) any_limit |= r.HasLimits();
    if (any_limit) {
      out.placeholders.push_back(
          "effort and velocity limits are 0 (the robot file has none)");
    }
  }

  std::ostringstream os;
  os << "<?xml version=\"1.0\"?>\n<!--\n  "
     << CommentText(ToolVersion() + ": " + CommandLine()) << "\n"
     << "  Robot '" << CommentText(robot.name) << "' ("
     << ToString(robot.convention)
     << " in the robot file) as URDF: forward kinematics equal to the "
        "file's.\n";
  if (out.not_exported.empty()) {
    os << "  Model extensions: none.\n";
  } else {
    os << "  NOT EXPORTED (URDF cannot express these model extensions; use "
          "the robot file with kincal for them):\n";
    for (const std::string& s : out.not_exported) {
      os << "    " << CommentText(s) << "\n";
    }
  }
  for (const std::string& s : out.placeholders) {
    os << "  Placeholder: " << CommentText(s) << "\n";
  }
  os << "-->\n<robot name=\"" << XmlEscape(robot.name) << "\">\n";
  os << "  <link name=\"base_link\"/>\n";
  for (int k = 0; k < n; ++k) {
    os << "  <link name=\"" << XmlEscape(link_name(k)) << "\"/>\n";
  }
  os << "  <link name=\"tip\"/>\n";
  os << joints.str();
  os << "  <joint name=\"tool\" type=\"fixed\">\n    <parent link=\""
     << XmlEscape(link_name(n - 1)) << "\"/>\n    <child link=\"tip\"/>\n    "
     << Origin(tool) << "\n  </joint>\n</robot>\n";
  out.xml = os.str();
  return out;
}

Robot ConvertToDh(const Robot& robot) {
  const Chain chain = Chain::FromRobot(robot);
  const int n = chain.num_joints();
  Require(n > 0, "robot '" + robot.name + "' has no joints");
  std::vector<Eigen::Vector3d> origins, axes;
  const std::vector<double> zero(n, 0.0);
  JointAxesInBase(chain, zero, &origins, &axes);
  const Eigen::Matrix4d tip = BaseFromTipAt(chain, zero);

  constexpr double kTol = 1e-9;
  // Below this sine of the angle between consecutive axes the row takes
  // Hayati's beta instead of a common normal.
  constexpr double kNearParallel = 1e-3;
  const Eigen::Vector3d z0 = Eigen::Vector3d::UnitZ();
  const bool prismatic0 = chain.rows[0].type == JointType::kPrismatic;
  const bool on_axis = prismatic0 || origins[0].head<2>().norm() < 1e-7;
  // The sine of the tilt, not 1 - cos: a tilt of 4.5e-5 rad passed
  // 1 - cos < 1e-9 and the conversion, which drops it, was 1.2e-5 mm off.
  const bool along_z = axes[0].dot(z0) > 0 && axes[0].cross(z0).norm() < kTol;
  if (!along_z || !on_axis) {
    std::ostringstream msg;
    msg << "robot '" << robot.name << "': standard DH needs joint 1 ("
        << robot.joints[0].name << ") to move about the base z axis"
        << (prismatic0 ? "" : " through the base origin") << "; its axis is ("
        << Short(axes[0].x()) << ", " << Short(axes[0].y()) << ", "
        << Short(axes[0].z()) << ") through (" << Short(origins[0].x()) << ", "
        << Short(origins[0].y()) << ", " << Short(origins[0].z())
        << ") mm. Express the robot in another base frame, or keep URDF";
    throw InputError(msg.str());
  }

  Robot dh;
  dh.name = robot.name;
  dh.convention = Convention::kDh;
  dh.gravity = robot.gravity;
  dh.bound_length_mm = robot.bound_length_mm;
  dh.bound_angle_deg = robot.bound_angle_deg;
  dh.extensions = robot.extensions;

  // Frame k-1 (origin o, axes x, z) sits on joint k's axis. Each step finds
  // frame k on the next line (point p, direction w) by the common normal.
  Eigen::Vector3d o = Eigen::Vector3d::Zero(), x = Eigen::Vector3d::UnitX(),
                  z = z0;
  for (int k = 0; k < n; ++k) {
    const bool last = k == n - 1;
    const Eigen::Vector3d p =
        last ? Eigen::Vector3d(tip.block<3, 1>(0, 3)) : origins[k + 1];
    const Eigen::Vector3d w =
        last ? Eigen::Vector3d(tip.block<3, 1>(0, 2)) : axes[k + 1];
    const Eigen::Vector3d c = z.cross(w);
    double d = 0.0, a = 0.0, alpha = 0.0, beta = 0.0;
    Eigen::Vector3d xn, on, x_next;
    if (c.norm() > kNearParallel) {  // skew or intersecting: the common normal
      xn = c.normalized();
      // o + t z and p + s w closest: solve the 2x2 normal equations.
      const Eigen::Vector3d r = p - o;
      const double b = z.dot(w), dz = z.dot(r), dw = w.dot(r);
      const double den = 1.0 - b * b;
      const double t = (dz - b * dw) / den;
      const double s = (b * dz - dw) / den;
      d = t;
      on = p + s * w;
      a = (on - (o + d * z)).dot(xn);
      alpha = std::atan2(z.cross(w).dot(xn), z.dot(w));
      x_next = xn;
    } else {
      // Parallel or nearly so: the common normal runs off to d ~ distance /
      // angle (a calibrated Panda's tip z against joint 7: d ~ 1e9 mm, the
      // conversion 1.2e-5 mm off), so Hayati's form: d = 0, the normal in
      // the plane through o normal to z to where the next line crosses it,
      // then Rx(alpha) Ry(beta) turn z onto w.
      const Eigen::Vector3d r = p - o;
      on = p - (r.dot(z) / w.dot(z)) * w;
      const Eigen::Vector3d v = on - o;  // normal to z
      xn = v.norm() > 1e-9 ? Eigen::Vector3d(v.normalized()) : x;
      a = v.dot(xn);
      const Eigen::Vector3d yn = z.cross(xn);
      beta = std::asin(std::clamp(w.dot(xn), -1.0, 1.0));
      alpha = std::atan2(-w.dot(yn), w.dot(z));
      x_next = std::cos(beta) * xn +
               std::sin(beta) * (std::sin(alpha) * yn - std::cos(alpha) * z);
    }
    const double theta = std::atan2(x.cross(xn).dot(z), x.dot(xn));
    RobotRow row = robot.joints[k];
    row.theta_deg = theta * kRadToDeg;
    row.d_mm = d;
    row.a_mm = a;
    row.alpha_deg = alpha * kRadToDeg;
    row.beta_deg = beta * kRadToDeg;
    row.xyz_mm.setZero();
    row.rpy_deg.setZero();
    row.axis = Eigen::Vector3d::UnitZ();
    dh.joints.push_back(row);
    o = on;
    x = x_next;
    z = w;
  }
  // Tool: frame n's z is the tip's z through the tip; Rz(theta) Tz(d).
  const Eigen::Vector3d tip_x = tip.block<3, 1>(0, 0);
  dh.tool = robot.tool;
  dh.tool.theta_deg =
      std::atan2(x.cross(tip_x).dot(z), x.dot(tip_x)) * kRadToDeg;
  dh.tool.d_mm = (Eigen::Vector3d(tip.block<3, 1>(0, 3)) - o).dot(z);
  dh.tool.a_mm = 0.0;
  dh.tool.alpha_deg = 0.0;
  dh.tool.beta_deg = 0.0;
  dh.tool.xyz_mm.setZero();
  dh.tool.rpy_deg.setZero();

  // Centres of mass are given in the frame after their row; that frame
  // changes with the convention, the link it is fixed to does not, so
  // com_dh = (base_from_dh_k)^-1 base_from_src_k com at any one q (0 here).
  const Chain out = Chain::FromRobot(dh);
  {
    Eigen::Matrix4d src = Eigen::Matrix4d::Identity(),
                    dst = Eigen::Matrix4d::Identity();
    for (int k = 0; k < n; ++k) {
      src = src * RowTransform<double>(chain.convention, chain.rows[k],
                                       chain.rows[k].p.data(), 0.0);
      dst = dst * RowTransform<double>(out.convention, out.rows[k],
                                       out.rows[k].p.data(), 0.0);
      RobotRow& row = dh.joints[k];
      if (!row.HasMass()) continue;
      const Eigen::Vector4d com_in_base =
          src * robot.joints[k].com_mm.homogeneous();
      row.com_mm = (dst.inverse() * com_in_base).head<3>();
    }
  }

  // Self-check over seeded random poses (an internal error, not bad input).
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-M_PI, M_PI);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> q(n);
    for (int k = 0; k < n; ++k) {
      q[k] =
          chain.rows[k].type == JointType::kPrismatic ? 100.0 * u(rng) : u(rng);
    }
    const Eigen::Matrix4d a = BaseFromTipAt(chain, q),
                          b = BaseFromTipAt(out, q);
    const double diff = (a - b).block<3, 4>(0, 0).cwiseAbs().maxCoeff();
    KINCAL_CHECK(diff < 1e-6,
                 "DH conversion of '" << robot.name << "' differs by " << diff);
  }
  return dh;
}

}  // namespace kincal
