#include "vision/calib_target.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "data/error.h"
#include "vision/apriltag_detector.h"

namespace kincal {

namespace {

const char* kUsage =
    "expected chessboard:COLSxROWS:SQUARE or "
    "aprilgrid:COLSxROWS:TAG_SIZE:SPACING_RATIO[:first=N][:order=rows|columns]"
    "[:origin=bottom-left|top-left][:rotation=0|90|180|270] (e.g. "
    "chessboard:9x6:25 or aprilgrid:6x6:30:0.3)";

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::string cur;
  std::istringstream is(s);
  while (std::getline(is, cur, sep)) parts.push_back(cur);
  if (!s.empty() && s.back() == sep) parts.push_back("");
  return parts;
}

int ParseCount(const std::string& s, const std::string& text) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size() || v <= 0 || v > 1000) {
    throw InputError("--target '" + text + "': '" + s +
                     "' is not a positive count; " + kUsage);
  }
  return static_cast<int>(v);
}

double ParsePositive(const std::string& s, const std::string& text,
                     const char* what) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !(v > 0) ||
      !std::isfinite(v)) {
    throw InputError("--target '" + text + "': " + what + " '" + s +
                     "' is not a positive number; " + kUsage);
  }
  return v;
}

// One KEY=VALUE layout option of an AprilGrid spec.
void ParseLayoutOption(const std::string& option, const std::string& text,
                       CalibTargetSpec* spec) {
  const size_t eq = option.find('=');
  const std::string key = option.substr(0, eq);
  const std::string value =
      eq == std::string::npos ? "" : option.substr(eq + 1);
  const auto bad = [&](const std::string& expected) {
    return InputError("--target '" + text + "': layout option '" + option +
                      "': expected " + expected);
  };
  if (key == "first") {
    char* end = nullptr;
    const long v = std::strtol(value.c_str(), &end, 10);
    if (value.empty() || *end != '\0' || v < 0) {
      throw bad("first=N, the first tag id (N >= 0)");
    }
    spec->first_id = static_cast<int>(std::min(v, 100000L));
  } else if (key == "order") {
    if (value != "rows" && value != "columns") {
      throw bad("order=rows or order=columns");
    }
    spec->column_major = value == "columns";
  } else if (key == "origin") {
    if (value != "bottom-left" && value != "top-left") {
      throw bad("origin=bottom-left or origin=top-left");
    }
    spec->origin_top = value == "top-left";
  } else if (key == "rotation") {
    if (value != "0" && value != "90" && value != "180" && value != "270") {
      throw bad("rotation=0, 90, 180 or 270 (degrees, counter-clockwise)");
    }
    spec->rotation_deg = std::stoi(value);
  } else {
    throw bad("first=, order=, origin= or rotation=");
  }
}

}  // namespace

Eigen::Vector2i CalibTargetSpec::TagCell(int index) const {
  int col = column_major ? index / rows : index % cols;
  int row = column_major ? index % rows : index / cols;
  if (origin_top) row = rows - 1 - row;
  return {col, row};
}

CalibTargetSpec ParseCalibTargetSpec(const std::string& text) {
  const std::vector<std::string> parts = Split(text, ':');
  CalibTargetSpec spec;
  spec.text = text;
  if (parts.empty()) throw InputError("--target '" + text + "': " + kUsage);
  if (parts[0] == "chessboard") {
    spec.kind = CalibTargetSpec::Kind::kChessboard;
    if (parts.size() != 3) {
      throw InputError("--target '" + text + "': " + kUsage);
    }
  } else if (parts[0] == "aprilgrid") {
    spec.kind = CalibTargetSpec::Kind::kAprilGrid;
    if (parts.size() < 4) {
      throw InputError("--target '" + text + "': " + kUsage);
    }
    for (size_t i = 4; i < parts.size(); ++i) {
      ParseLayoutOption(parts[i], text, &spec);
    }
  } else {
    throw InputError("--target '" + text + "': unknown target type '" +
                     parts[0] + "'; " + kUsage);
  }
  const std::vector<std::string> dims = Split(parts[1], 'x');
  if (dims.size() != 2) {
    throw InputError("--target '" + text + "': '" + parts[1] +
                     "' is not COLSxROWS; " + kUsage);
  }
  spec.cols = ParseCount(dims[0], text);
  spec.rows = ParseCount(dims[1], text);
  spec.size = ParsePositive(parts[2], text,
                            spec.kind == CalibTargetSpec::Kind::kChessboard
                                ? "square size"
                                : "tag size");
  if (spec.kind == CalibTargetSpec::Kind::kChessboard) {
    if (spec.cols < 2 || spec.rows < 2) {
      throw InputError("--target '" + text +
                       "': a chessboard needs at least 2x2 inner corners");
    }
  } else {
    spec.spacing_ratio = ParsePositive(parts[3], text, "spacing ratio");
    if (spec.first_id + spec.cols * spec.rows > TagFamilySize("tag36h11")) {
      throw InputError(
          "--target '" + text + "': ids " + std::to_string(spec.first_id) +
          ".." + std::to_string(spec.first_id + spec.cols * spec.rows - 1) +
          ", but tag36h11 has only " +
          std::to_string(TagFamilySize("tag36h11")) + " ids");
    }
  }
  return spec;
}

std::vector<Eigen::Vector3d> CalibTargetSpec::Points() const {
  std::vector<Eigen::Vector3d> pts;
  if (kind == Kind::kChessboard) {
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) pts.emplace_back(c * size, r * size, 0);
    }
    return pts;
  }
  const double pitch = size * (1.0 + spacing_ratio);
  // libapriltag corner order: bottom-left, bottom-right, top-right, top-left
  // (y up in the target frame).
  // A tag turned by 90 deg counter-clockwise has its corner k where the
  // upright tag has corner k + 1.
  const double dx[4] = {0, 1, 1, 0};
  const double dy[4] = {0, 0, 1, 1};
  const int turn = rotation_deg / 90;
  for (int index = 0; index < rows * cols; ++index) {
    const Eigen::Vector2i cell = TagCell(index);
    for (int k = 0; k < 4; ++k) {
      const int at = (k + turn) % 4;
      pts.emplace_back(cell.x() * pitch + dx[at] * size,
                       cell.y() * pitch + dy[at] * size, 0);
    }
  }
  return pts;
}

struct CalibTargetDetector::Impl {
  std::unique_ptr<AprilTagDetector> apriltag;
  std::vector<Eigen::Vector3d> points;
};

CalibTargetDetector::CalibTargetDetector(
    const CalibTargetSpec& spec, const std::optional<CameraIntrinsics>& lens)
    : spec_(spec), impl_(std::make_unique<Impl>()) {
  impl_->points = spec.Points();
  if (spec.kind == CalibTargetSpec::Kind::kAprilGrid) {
    AprilTagOptions options;
    options.lens = lens;
    impl_->apriltag = std::make_unique<AprilTagDetector>(options);
  }
}

CalibTargetDetector::~CalibTargetDetector() = default;

TargetObservation CalibTargetDetector::Detect(const cv::Mat& gray) {
  KINCAL_CHECK(gray.type() == CV_8UC1, "Detect needs an 8-bit gray image");
  TargetObservation obs;
  if (spec_.kind == CalibTargetSpec::Kind::kChessboard) {
    std::vector<cv::Point2f> corners;
    const cv::Size size(spec_.cols, spec_.rows);
    if (!cv::findChessboardCorners(
            gray, size, corners,
            cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      return obs;
    }
    cv::cornerSubPix(
        gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30,
                         0.01));
    for (size_t i = 0; i < corners.size(); ++i) {
      obs.p_in_target.push_back(impl_->points[i]);
      obs.pixels.emplace_back(corners[i].x, corners[i].y);
    }
    return obs;
  }
  const int num_tags = spec_.cols * spec_.rows;
  const std::vector<TagDetection> dets = impl_->apriltag->Detect(gray);
  std::vector<int> count(num_tags, 0);
  const auto index_of = [&](int id) { return id - spec_.first_id; };
  for (const TagDetection& det : dets) {
    const int i = index_of(det.id);
    if (i >= 0 && i < num_tags) ++count[i];
  }
  for (const TagDetection& det : dets) {
    // Ids outside the grid, and ids seen twice (a false decode), are dropped.
    const int i = index_of(det.id);
    if (i < 0 || i >= num_tags || count[i] != 1) continue;
    for (int k = 0; k < 4; ++k) {
      if (!det.usable[k]) continue;
      obs.p_in_target.push_back(impl_->points[4 * i + k]);
      obs.pixels.push_back(det.corners[k]);
    }
  }
  return obs;
}

}  // namespace kincal
