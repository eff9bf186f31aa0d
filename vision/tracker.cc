#include "vision/tracker.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "data/error.h"

namespace kincal {

void TrackerOptions::Check() const {
  detector.Check();
  auto fail = [](const char* what, double v) {
    std::ostringstream os;
    os << "tracker option " << what << " = " << v;
    throw InputError(os.str());
  };
  if (!(margin_ratio >= 0)) fail("margin_ratio (expected >= 0)", margin_ratio);
  if (!(min_margin_px >= 0))
    fail("min_margin_px (expected >= 0)", min_margin_px);
  if (full_search_interval < 0) {
    fail("full_search_interval (expected >= 0)", full_search_interval);
  }
}

TagTracker::TagTracker(const TrackerOptions& options)
    : options_(options), detector_(options.detector) {
  options_.Check();
}

void TagTracker::Reset() {
  previous_.clear();
  before_previous_.clear();
}

std::vector<TagDetection> TagTracker::FullSearch(const cv::Mat& gray) {
  ++full_searches_;
  since_full_ = 0;
  regions_.clear();
  return detector_.Detect(gray);
}

std::vector<TagDetection> TagTracker::Track(const cv::Mat& gray) {
  ++frames_;
  ++since_full_;
  std::vector<TagDetection> found;
  const bool periodic = options_.full_search_interval > 0 &&
                        since_full_ >= options_.full_search_interval;
  if (!options_.enabled || previous_.empty() || periodic) {
    found = FullSearch(gray);
  } else {
    // Predicted regions.
    std::map<int, const TagDetection*> older;
    for (const auto& d : before_previous_) older[d.id] = &d;
    std::vector<cv::Rect> rects;
    const cv::Rect image(0, 0, gray.cols, gray.rows);
    for (const auto& d : previous_) {
      Eigen::Vector2d motion = Eigen::Vector2d::Zero();
      const auto it = older.find(d.id);
      if (it != older.end()) motion = d.center - it->second->center;
      double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18, edge = 0;
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d p = d.corners[k] + motion;
        x0 = std::min(x0, p.x());
        y0 = std::min(y0, p.y());
        x1 = std::max(x1, p.x());
        y1 = std::max(y1, p.y());
        edge = std::max(edge, (d.corners[(k + 1) % 4] - d.corners[k]).norm());
      }
      const double m =
          std::max(options_.min_margin_px, options_.margin_ratio * edge) +
          motion.norm();
      cv::Rect r(cv::Point(static_cast<int>(std::floor(x0 - m)),
                           static_cast<int>(std::floor(y0 - m))),
                 cv::Point(static_cast<int>(std::ceil(x1 + m)),
                           static_cast<int>(std::ceil(y1 + m))));
      r &= image;
      if (r.area() > 0) rects.push_back(r);
    }
    // Merge overlapping regions until none overlap.
    bool merged = true;
    while (merged) {
      merged = false;
      for (size_t i = 0; i < rects.size() && !merged; ++i) {
        for (size_t j = i + 1; j < rects.size() && !merged; ++j) {
          if ((rects[i] & rects[j]).area() > 0) {
            rects[i] |= rects[j];
            rects.erase(rects.begin() + j);
            merged = true;
          }
        }
      }
    }
    regions_ = rects;
    std::map<int, TagDetection> by_id;
    for (const cv::Rect& r : rects) {
      for (const TagDetection& d : detector_.DetectInRegion(gray, r)) {
        by_id.emplace(d.id, d);  // a tag found twice: keep the first
      }
    }
    for (auto& kv : by_id) found.push_back(kv.second);
    // Lost a tag: search the whole frame.
    if (found.size() < previous_.size()) found = FullSearch(gray);
  }
  before_previous_ = std::move(previous_);
  previous_ = found;
  return found;
}

}  // namespace kincal
