#include "camcal/plausibility.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace kincal {
namespace {

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// spec_text with its size field (the third ':' field) multiplied by 1000.
std::string InMillimetres(const std::string& spec_text, double size) {
  const size_t first = spec_text.find(':');
  const size_t second =
      first == std::string::npos ? first : spec_text.find(':', first + 1);
  if (second == std::string::npos) return "";
  const size_t end = spec_text.find(':', second + 1);
  return spec_text.substr(0, second + 1) + Number(size * 1000) +
         (end == std::string::npos ? "" : spec_text.substr(end));
}

std::string MetresAdvice(double size, const std::string& spec_text) {
  const std::string fixed = InMillimetres(spec_text, size);
  return "the board size looks like metres: give it in mm" +
         (fixed.empty()
              ? std::string(" (x1000)")
              : ", e.g. --target " + fixed + " (" + Number(size) + " x 1000)") +
         "; if the board really is this small, add --tiny-board";
}

bool IsSquaresUnit(double size) { return size == 1.0; }

}  // namespace

std::string BoardSizeImplausible(double size, const std::string& spec_text,
                                 const BoardPlausibilityOptions& options) {
  if (IsSquaresUnit(size) || size >= options.min_size_mm) return "";
  return "--target '" + spec_text + "': a square or tag of " + Number(size) +
         " mm; " + MetresAdvice(size, spec_text);
}

double MedianBoardDistance(const CalibrationSummary& summary) {
  const Rigid3 rig_from_cam0 =
      summary.rig.cameras.empty()
          ? Rigid3()
          : summary.rig.cameras[0].cam_from_rig.Inverse();
  std::vector<double> distances;
  for (size_t v = 0; v < summary.rig_from_target.size(); ++v) {
    if (v < summary.view_used.size() && !summary.view_used[v]) continue;
    const Eigen::Vector3d t = summary.rig_from_target[v].t - rig_from_cam0.t;
    if (t.allFinite()) distances.push_back(t.norm());
  }
  if (distances.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t mid = distances.size() / 2;
  std::nth_element(distances.begin(), distances.begin() + mid, distances.end());
  return distances[mid];
}

std::string SolvedRigImplausible(const CalibrationSummary& summary, double size,
                                 const std::string& spec_text,
                                 const BoardPlausibilityOptions& options) {
  if (IsSquaresUnit(size)) return "";
  const double distance = MedianBoardDistance(summary);
  if (std::isfinite(distance) && distance < options.min_distance_mm) {
    return "the board is seen " + Number(distance) +
           " mm from the camera (median over the views): " +
           MetresAdvice(size, spec_text);
  }
  if (summary.rig.cameras.size() >= 2 &&
      summary.baseline < options.min_baseline_mm) {
    return "the cameras are " + Number(summary.baseline) +
           " mm apart: " + MetresAdvice(size, spec_text);
  }
  return "";
}

}  // namespace kincal
