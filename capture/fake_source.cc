// A synthetic live camera (`fake:<name>?width=..&height=..&fps=..`): frames
// on the host monotonic clock at exact multiples of 1/fps (two fake cameras
// at the same rate give identical timestamps, like hardware-triggered
// ones), paced in real time, 8-bit gray: a checkerboard scene with sensor-
// like noise (4 noise patterns, cycled) and a bright bar that moves with the
// frame number. With mosaic=RGGB (or GRBG, GBRG, BGGR) the frames are a
// colour sensor's raw mosaic of that scene: each photosite scaled by its
// filter's response (red 0.55, green 1, blue 0.75 of the gray scene). For
// tests, benchmarks and the lab procedure without cameras; like any live
// camera it never ends.

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "capture/frame_source.h"

namespace kincal::capture {
namespace {

// The gray scene seen through the colour filters of `mosaic` (RGGB ...):
// every photosite scaled by its filter's response to gray.
void ApplyFilterResponses(const std::string& mosaic, cv::Mat* image) {
  for (int r = 0; r < image->rows; ++r) {
    uint8_t* row = image->ptr<uint8_t>(r);
    for (int c = 0; c < image->cols; ++c) {
      const char filter = mosaic[2 * (r % 2) + c % 2];
      const double gain = filter == 'R' ? 0.55 : (filter == 'B' ? 0.75 : 1.0);
      row[c] = static_cast<uint8_t>(std::lround(gain * row[c]));
    }
  }
}

class FakeSource : public FrameSource {
 public:
  explicit FakeSource(const SourceUri& uri)
      : name_(uri.path),
        width_(uri.GetInt("width", 640, 16, 16384)),
        height_(uri.GetInt("height", 480, 16, 16384)),
        fps_(uri.GetDouble("fps", 30, 0.1, 1000)),
        mosaic_(DeclaredMosaic(uri)) {}

  Status Open() override {
    scenes_.clear();
    for (int k = 0; k < 4; ++k) {
      cv::Mat gray(height_, width_, CV_8UC1);
      for (int r = 0; r < height_; ++r) {
        uint8_t* row = gray.ptr<uint8_t>(r);
        for (int c = 0; c < width_; ++c) {
          row[c] = static_cast<uint8_t>(60 + 40 * ((r / 64 + c / 64) % 2) +
                                        (r + c) / 40 % 100);
        }
      }
      cv::Mat noise(height_, width_, CV_16SC1);
      cv::RNG rng(1234 + k + 17 * static_cast<int>(name_.size()));
      rng.fill(noise, cv::RNG::NORMAL, 0, 2);
      cv::Mat wide;
      gray.convertTo(wide, CV_16SC1);
      wide += noise;
      wide.convertTo(gray, CV_8UC1);
      scenes_.push_back(gray);
    }
    // The next frame time on the global grid of 1/fps.
    next_tick_ = static_cast<int64_t>(std::ceil(MonotonicSeconds() * fps_));
    sequence_ = 0;
    open_ = true;
    return Status::Ok();
  }

  Status Grab(Frame* frame) override {
    if (!open_) {
      return Status::Error(Status::Kind::kIoError,
                           "fake camera '" + name_ + "': not open");
    }
    const double t = next_tick_ / fps_;
    const double wait = t - MonotonicSeconds();
    if (wait > 0) {
      std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    }
    frame->image = scenes_[sequence_ % scenes_.size()].clone();
    const int bar = static_cast<int>((sequence_ * 8) % width_);
    cv::rectangle(frame->image, cv::Rect(bar, 0, 8, height_), cv::Scalar(230),
                  cv::FILLED);
    if (!mosaic_.empty()) ApplyFilterResponses(mosaic_, &frame->image);
    frame->timestamp_s = t;
    frame->sequence = sequence_++;
    ++next_tick_;
    return Status::Ok();
  }

  Status Close() override {
    open_ = false;
    return Status::Ok();
  }
  std::string Describe() const override {
    return "fake camera '" + name_ + "' " + std::to_string(width_) + "x" +
           std::to_string(height_) +
           (mosaic_.empty() ? " gray " : " raw " + mosaic_ + " ") +
           std::to_string(fps_) + " fps";
  }
  bool IsLive() const override { return true; }
  TimeBase time_base() const override { return TimeBase::kHostMonotonic; }
  std::string mosaic() const override { return mosaic_; }

 private:
  std::string name_;
  int width_, height_;
  double fps_;
  std::string mosaic_;  // raw mosaic pattern, empty for gray frames
  std::vector<cv::Mat> scenes_;
  int64_t next_tick_ = 0;
  int64_t sequence_ = 0;
  bool open_ = false;
};

}  // namespace

std::unique_ptr<FrameSource> MakeFakeSource(const SourceUri& uri) {
  return std::make_unique<FakeSource>(uri);
}

}  // namespace kincal::capture
