#ifndef KINCAL_CAPTURE_FRAME_GRABBER_H_
#define KINCAL_CAPTURE_FRAME_GRABBER_H_

#include <cstdint>
#include <optional>
#include <vector>

#include "capture/frame_source.h"

namespace kincal::capture {

// One frame of every camera, taken together.
struct FrameSet {
  std::vector<Frame> frames;  // one per source, in the grabber's source order
  int64_t index = 0;          // 0, 1, 2, ... in the order sets were made
};

struct FrameGrabberOptions {
  enum class Pairing {
    kAuto,              // lock step for replay sources, by time for cameras
    kLockStep,          // the n-th frame of every source together
    kNearestTimestamp,  // frames whose timestamps span <= tolerance_s
  };
  Pairing pairing = Pairing::kAuto;
  // Largest difference between the timestamps of a set (latest - earliest).
  // Keep it below half the frame period (10 ms suits free-running cameras up
  // to 50 fps; hardware-triggered cameras agree to well under 1 ms).
  double tolerance_s = 0.010;
  // Consecutive unmatched frames (over all sources) after which Grab gives
  // up with kIoError (the cameras run at different rates or on different
  // clocks).
  int max_consecutive_drops = 100;
};

// Groups the frames of 1..N sources into sets, one frame per source (one
// source: every frame is a set). The sources are not owned and must outlive
// the grabber. Not thread-safe.
//
// By time: every source keeps one pending frame. A pending frame earlier
// than the latest pending frame by more than tolerance_s cannot be in a set
// any more (frames of one source come in time order, and the latest
// source's later frames are later still), so it is dropped and counted for
// its source, and that source grabs again; when every pending frame lies
// within tolerance_s of the latest, they are a set. A timeout on one source
// keeps the other sources' frames, so calling Grab again continues where it
// stopped.
//
// In lock step: the n-th frame of every source. When one source ends, the
// frames already grabbed from the others in that round, and one more frame
// grabbed from each later source, count as drops and as a length mismatch.
class FrameGrabber {
 public:
  using Pairing = FrameGrabberOptions::Pairing;

  FrameGrabber(std::vector<FrameSource*> sources,
               FrameGrabberOptions options = {});
  ~FrameGrabber();

  // Opens every source (closing those already open when one fails).
  // kUnsupported when pairing by time is asked for sources on different
  // clocks (a camera with a replay source), or when there is no source.
  Status Open();
  // The next set; kEndOfStream when a replay source is exhausted.
  Status Grab(FrameSet* set);
  Status Close();

  // The pairing in use (kAuto resolved).
  Pairing pairing() const { return pairing_; }
  size_t cameras() const { return sources_.size(); }
  int64_t sets() const { return sets_; }
  // Frames of source k left out of every set.
  int64_t dropped(size_t k) const { return dropped_[k]; }
  const std::vector<int64_t>& dropped() const { return dropped_; }
  // Lock step only: one source ended while another still had frames.
  bool length_mismatch() const { return length_mismatch_; }

 private:
  Status GrabLockStep(FrameSet* set);
  Status GrabByTime(FrameSet* set);

  std::vector<FrameSource*> sources_;
  FrameGrabberOptions options_;
  Pairing pairing_;
  bool open_ = false;
  std::vector<std::optional<Frame>> pending_;  // by time: per source
  int64_t sets_ = 0;
  std::vector<int64_t> dropped_;
  bool length_mismatch_ = false;
};

const char* PairingName(FrameGrabberOptions::Pairing pairing);

// What a set of `cameras` frames is called in messages: "frames" (one
// camera), "pairs" (two), "frame sets" (more).
const char* FrameSetNoun(size_t cameras);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_FRAME_GRABBER_H_
