#ifndef KINCAL_CAPTURE_STEREO_GRABBER_H_
#define KINCAL_CAPTURE_STEREO_GRABBER_H_

#include <cstdint>
#include <optional>

#include "capture/frame_source.h"

namespace kincal::capture {

// One left/right pair.
struct StereoFrame {
  Frame left;
  Frame right;
  int64_t index = 0;  // 0, 1, 2, ... in the order pairs were made
};

struct StereoGrabberOptions {
  enum class Pairing {
    kAuto,              // lock step for replay sources, by time for cameras
    kLockStep,          // n-th left frame with n-th right frame
    kNearestTimestamp,  // frames whose timestamps differ by <= tolerance_s
  };
  Pairing pairing = Pairing::kAuto;
  // Largest |t_left - t_right| of a pair. Keep it below half the frame
  // period (10 ms suits free-running cameras up to 50 fps; hardware-triggered
  // cameras agree to well under 1 ms).
  double tolerance_s = 0.010;
  // Consecutive unmatched frames after which Grab gives up with kIoError
  // (the cameras run at different rates or on different clocks).
  int max_consecutive_drops = 100;
};

// Pairs the frames of two sources. The sources are not owned and must
// outlive the grabber. Not thread-safe.
//
// By time: both sides keep one pending frame; when the two differ by more
// than tolerance_s the earlier one cannot have a partner any more (frames of
// one source come in time order), so it is dropped and counted, and that
// side grabs again. A timeout on one side keeps the other side's frame, so
// calling Grab again continues where it stopped.
class StereoGrabber {
 public:
  using Pairing = StereoGrabberOptions::Pairing;

  StereoGrabber(FrameSource* left, FrameSource* right,
                StereoGrabberOptions options = {});
  ~StereoGrabber();

  // Opens both sources (closing the first when the second fails).
  // kUnsupported when pairing by time is asked for sources on different
  // clocks (a camera with a replay source).
  Status Open();
  // The next pair; kEndOfStream when a replay source is exhausted.
  Status Grab(StereoFrame* pair);
  Status Close();

  // The pairing in use (kAuto resolved).
  Pairing pairing() const { return pairing_; }
  int64_t pairs() const { return pairs_; }
  int64_t dropped_left() const { return dropped_left_; }
  int64_t dropped_right() const { return dropped_right_; }
  // Lock step only: one source ended while the other still had frames.
  bool length_mismatch() const { return length_mismatch_; }

 private:
  Status GrabLockStep(StereoFrame* pair);
  Status GrabByTime(StereoFrame* pair);

  FrameSource* left_;
  FrameSource* right_;
  StereoGrabberOptions options_;
  Pairing pairing_;
  bool open_ = false;
  std::optional<Frame> pending_left_;
  std::optional<Frame> pending_right_;
  int64_t pairs_ = 0;
  int64_t dropped_left_ = 0;
  int64_t dropped_right_ = 0;
  bool length_mismatch_ = false;
};

const char* PairingName(StereoGrabberOptions::Pairing pairing);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_STEREO_GRABBER_H_
