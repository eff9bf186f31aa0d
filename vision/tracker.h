#ifndef KINCAL_VISION_TRACKER_H_
#define KINCAL_VISION_TRACKER_H_

// Frame-to-frame tag tracking for one camera: each tag's corners are
// predicted from the last two frames (constant velocity), the detector runs
// only in the predicted regions (overlapping regions merged), and the whole
// frame is searched only when there is no track yet, when a tracked tag was
// lost, or every full_search_interval frames (to pick up new tags).

#include <opencv2/core.hpp>
#include <vector>

#include "vision/apriltag_detector.h"

namespace kincal {

struct TrackerOptions {
  AprilTagOptions detector;
  // Region = predicted corners' bounding box grown by
  // max(min_margin_px, margin_ratio * tag edge in px) + predicted motion.
  double margin_ratio = 0.5;
  double min_margin_px = 16;
  // Full-frame search every this many frames (0 = only when lost).
  int full_search_interval = 50;
  bool enabled = true;  // false: full-frame detection on every frame

  void Check() const;  // InputError naming the bad option
};

class TagTracker {
 public:
  explicit TagTracker(const TrackerOptions& options = TrackerOptions());

  // Detections in this frame (OpenCV pixels, full-image coordinates).
  std::vector<TagDetection> Track(const cv::Mat& gray);
  // Forgets the tracks (next frame is a full search).
  void Reset();

  int frames() const { return frames_; }
  int full_searches() const { return full_searches_; }
  // Regions searched in the last frame (empty after a full search).
  const std::vector<cv::Rect>& last_regions() const { return regions_; }

 private:
  std::vector<TagDetection> FullSearch(const cv::Mat& gray);

  TrackerOptions options_;
  AprilTagDetector detector_;
  std::vector<TagDetection> previous_;
  std::vector<TagDetection> before_previous_;
  std::vector<cv::Rect> regions_;
  int frames_ = 0;
  int full_searches_ = 0;
  int since_full_ = 0;
};

}  // namespace kincal

#endif  // KINCAL_VISION_TRACKER_H_
