#include "synth/povray_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "data/error.h"
#include "vision/apriltag_detector.h"

namespace kincal {
namespace {

std::string Vec(const Eigen::Vector3d& v) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "<%.9g, %.9g, %.9g>", v.x(), v.y(), v.z());
  return buf;
}

// POV-Ray's `matrix` of the affine p -> A p + t (rows: A's columns, then t).
std::string PovMatrix(const Eigen::Matrix3d& A, const Eigen::Vector3d& t) {
  std::string m = "matrix <";
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d v = k < 3 ? Eigen::Vector3d(A.col(k)) : t;
    char buf[128];
    std::snprintf(buf, sizeof buf, "%s%.9g, %.9g, %.9g", k ? ", " : "", v.x(),
                  v.y(), v.z());
    m += buf;
  }
  return m + ">";
}

std::string Square(double a, double b) {
  std::ostringstream os;
  os << "polygon { 5, <" << a << ", " << a << ">, <" << b << ", " << a << ">, <"
     << b << ", " << b << ">, <" << a << ", " << b << ">, <" << a << ", " << a
     << ">\n";
  return os.str();
}

const char kPaperFinish[] =
    "  finish { ambient 0 diffuse 1 specular 0.02 roughness 0.1 }\n";

// Each tag: the printed image on paper, more paper around it if asked, and
// the anodised plate behind (z into the tag), as large as the paper: a
// larger one would reach into the neighbouring tags of a target whose tags
// touch.
std::string TagObjects(const Target& target, const Rigid3& cam_from_tool,
                       const PovSceneOptions& options) {
  std::ostringstream os;
  for (const TargetTag& tag : target.tags) {
    const cv::Mat image = TagImage(target.family, tag.id);
    const double cell = tag.size_mm / TagBlackSquareCells(target.family);
    const double n = image.cols * cell, half = n / 2;
    const Rigid3 cam_from_tag = cam_from_tool * tag.tool_from_tag;
    // POV's image square (0..1, the image's top row at y = 1) -> the tag
    // frame (x right, y down the printed image, origin at the centre).
    Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
    S(0, 0) = n;
    S(1, 1) = -n;
    const Eigen::Vector3d s0(-half, half, 0);
    os << Square(0, 1) << "  pigment { image_pattern { pgm \"tag_" << tag.id
       << ".pgm\" interpolate 0 once }\n"
       << "    color_map { [0 rgb 0.04] [1 rgb 0.82] } }\n"
       << kPaperFinish << "  "
       << PovMatrix(cam_from_tag.R * S, cam_from_tag.R * s0 + cam_from_tag.t)
       << " }\n";
    const double m = half + options.margin_cells * cell;
    if (options.margin_cells > 0) {
      os << Square(-m, m) << "  pigment { rgb 0.82 }\n"
         << kPaperFinish << "  translate <0, 0, 0.05> "
         << PovMatrix(cam_from_tag.R, cam_from_tag.t) << " }\n";
    }
    os << "box { <" << -m << ", " << -m << ", 0.15>, <" << m << ", " << m
       << ", 4>\n  pigment { rgb 0.18 }\n"
       << "  finish { ambient 0 diffuse 0.7 specular 0.35 roughness 0.02 "
          "metallic }\n"
       << "  " << PovMatrix(cam_from_tag.R, cam_from_tag.t) << " }\n";
  }
  return os.str();
}

// The needle from a little past the middle of the tags to the tip.
std::string NeedleObject(const Target& target, const Rigid3& cam_from_tool) {
  if (!target.has_tip || target.tags.empty()) return "";
  Eigen::Vector3d base = Eigen::Vector3d::Zero();
  for (const TargetTag& tag : target.tags) base += tag.tool_from_tag.t;
  base /= static_cast<double>(target.tags.size());
  const Eigen::Vector3d tip = target.tip_in_tool;
  base += 0.15 * (tip - base);
  const double radius = std::clamp(0.005 * (tip - base).norm(), 0.3, 1.5);
  const Eigen::Vector3d cone = tip + 0.05 * (base - tip);
  std::ostringstream os;
  os << "union { cylinder { " << Vec(base) << ", " << Vec(cone) << ", "
     << radius << " }\n"
     << "  cone { " << Vec(cone) << ", " << radius << ", " << Vec(tip)
     << ", 0.02 }\n"
     << "  pigment { rgb 0.6 } finish { ambient 0 diffuse 0.5 specular 0.6 "
        "roughness 0.01 metallic }\n"
     << "  " << PovMatrix(cam_from_tool.R, cam_from_tool.t) << " }\n";
  return os.str();
}

// The lights and the table, placed in the rig frame, written in the
// camera's.
std::string Surroundings(const Rigid3& cam_from_rig, double depth_mm,
                         const PovSceneOptions& options) {
  const double a = options.light_deg * M_PI / 180;
  const double r = options.light_distance * depth_mm;
  const Eigen::Vector3d light =
      cam_from_rig *
      Eigen::Vector3d(-r * std::cos(a), -r * std::sin(a), depth_mm / 3);
  const double size = 0.17 * depth_mm;  // the lamp's diameter
  const Eigen::Vector3d axis1 = cam_from_rig.R * Eigen::Vector3d(0, size, 0);
  const Eigen::Vector3d axis2 = cam_from_rig.R * Eigen::Vector3d(0, 0, size);
  const Eigen::Vector3d fill = cam_from_rig * Eigen::Vector3d(0, -80, 0);
  const Eigen::Vector3d normal = cam_from_rig.R * Eigen::Vector3d(0, 0, -1);
  const Eigen::Vector3d table =
      cam_from_rig * Eigen::Vector3d(0, 0, options.table_depth * depth_mm);
  std::ostringstream os;
  os << "light_source { " << Vec(light) << " rgb 1.0\n  area_light "
     << Vec(axis1) << ", " << Vec(axis2)
     << ", 6, 6 adaptive 1 jitter circular orient }\n"
     << "light_source { " << Vec(fill) << " rgb 0.12 shadowless }\n"
     << "plane { " << Vec(normal) << ", " << normal.dot(table) << "\n"
     << "  pigment { checker rgb 0.22 rgb 0.3 scale " << 0.08 * depth_mm
     << " }\n  finish { ambient 0 diffuse 0.8 } }\n";
  return os.str();
}

}  // namespace

void PovSceneOptions::Check() const {
  auto in_range = [](const char* what, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi)) {
      std::ostringstream os;
      os << "POV-Ray scene option " << what << " = " << v << " (expected " << lo
         << ".." << hi << ")";
      throw InputError(os.str());
    }
  };
  in_range("light_deg", light_deg, -360, 360);
  in_range("light_distance", light_distance, 0.1, 100);
  in_range("margin_cells", margin_cells, 0, 10);
  in_range("table_depth", table_depth, 1.05, 100);
}

// POV-Ray samples pixel column i at (i + 0.5) / W of the screen and the ray
// goes through direction + (s - 0.5) right + (0.5 - t) up; with right =
// W / fx, up = -H / fy (row 0 at the top, y down as in OpenCV) the
// direction's offset puts the principal point at (cx, cy).
std::string PovCamera(const CameraIntrinsics& in) {
  const double W = in.width, H = in.height;
  const Eigen::Vector3d dir((W / 2 - 0.5 - in.cx) / in.fx,
                            (H / 2 - 0.5 - in.cy) / in.fy, 1.0);
  return "camera { perspective location <0, 0, 0>\n  direction " + Vec(dir) +
         "\n  right " + Vec({W / in.fx, 0, 0}) + "\n  up " +
         Vec({0, -H / in.fy, 0}) + " }\n";
}

std::string PovViewScene(const CameraIntrinsics& camera,
                         const Rigid3& cam_from_rig, const Target& target,
                         const Rigid3& rig_from_tool, double depth_mm,
                         const PovSceneOptions& options) {
  options.Check();
  KINCAL_CHECK(depth_mm > 0, "PovViewScene: depth_mm must be positive");
  const Rigid3 cam_from_tool = cam_from_rig * rig_from_tool;
  return "#version 3.7;\nglobal_settings { assumed_gamma 1.0 "
         "max_trace_level 6 }\n" +
         PovCamera(camera) + TagObjects(target, cam_from_tool, options) +
         NeedleObject(target, cam_from_tool) +
         Surroundings(cam_from_rig, depth_mm, options);
}

void WriteTagImages(const Target& target, const std::string& dir) {
  for (const TargetTag& tag : target.tags) {
    const std::string path = dir + "/tag_" + std::to_string(tag.id) + ".pgm";
    if (!cv::imwrite(path, TagImage(target.family, tag.id)))
      throw InputError(path + ": cannot write the tag image");
  }
}

cv::Mat SensorImage(const cv::Mat& rendered, double read_noise, double shot,
                    std::mt19937_64* rng) {
  cv::Mat gray;
  if (rendered.channels() == 3)
    cv::cvtColor(rendered, gray, cv::COLOR_BGR2GRAY);
  else
    gray = rendered.clone();
  KINCAL_CHECK(gray.type() == CV_8UC1, "SensorImage: expected 8-bit images");
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int r = 0; r < gray.rows; ++r) {
    uint8_t* row = gray.ptr<uint8_t>(r);
    for (int c = 0; c < gray.cols; ++c) {
      const double sd = std::sqrt(read_noise * read_noise + shot * row[c]);
      row[c] = cv::saturate_cast<uint8_t>(row[c] + sd * gauss(*rng));
    }
  }
  return gray;
}

}  // namespace kincal
