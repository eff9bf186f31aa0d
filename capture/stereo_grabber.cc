#include "capture/stereo_grabber.h"

#include <cmath>
#include <sstream>
#include <utility>

namespace kincal::capture {

const char* PairingName(StereoGrabberOptions::Pairing pairing) {
  switch (pairing) {
    case StereoGrabberOptions::Pairing::kAuto:
      return "auto";
    case StereoGrabberOptions::Pairing::kLockStep:
      return "lockstep";
    case StereoGrabberOptions::Pairing::kNearestTimestamp:
      return "timestamp";
  }
  return "?";
}

StereoGrabber::StereoGrabber(FrameSource* left, FrameSource* right,
                             StereoGrabberOptions options)
    : left_(left), right_(right), options_(options), pairing_(options.pairing) {
  if (pairing_ == Pairing::kAuto) {
    pairing_ = left_->IsLive() || right_->IsLive() ? Pairing::kNearestTimestamp
                                                   : Pairing::kLockStep;
  }
}

StereoGrabber::~StereoGrabber() { Close(); }

Status StereoGrabber::Open() {
  if (pairing_ == Pairing::kNearestTimestamp &&
      left_->time_base() != right_->time_base()) {
    return Status::Error(Status::Kind::kUnsupported,
                         "cannot pair by time: left (" + left_->Describe() +
                             ") runs on " + TimeBaseName(left_->time_base()) +
                             " time, right (" + right_->Describe() + ") on " +
                             TimeBaseName(right_->time_base()) +
                             " time; use two cameras or two recordings");
  }
  Status s = left_->Open();
  if (!s.ok()) return s;
  s = right_->Open();
  if (!s.ok()) {
    left_->Close();
    return s;
  }
  open_ = true;
  return Status::Ok();
}

Status StereoGrabber::Close() {
  if (!open_) return Status::Ok();
  open_ = false;
  pending_left_.reset();
  pending_right_.reset();
  Status a = left_->Close();
  Status b = right_->Close();
  return a.ok() ? b : a;
}

Status StereoGrabber::Grab(StereoFrame* pair) {
  if (!open_) {
    return Status::Error(Status::Kind::kIoError, "stereo grabber not open");
  }
  Status s =
      pairing_ == Pairing::kLockStep ? GrabLockStep(pair) : GrabByTime(pair);
  if (s.ok()) pair->index = pairs_++;
  return s;
}

Status StereoGrabber::GrabLockStep(StereoFrame* pair) {
  Status s = left_->Grab(&pair->left);
  if (s.kind() == Status::Kind::kEndOfStream) {
    Frame extra;
    if (right_->Grab(&extra).ok()) {
      length_mismatch_ = true;
      ++dropped_right_;
    }
    return s;
  }
  if (!s.ok()) return s;
  s = right_->Grab(&pair->right);
  if (s.kind() == Status::Kind::kEndOfStream) {
    length_mismatch_ = true;
    ++dropped_left_;
  }
  return s;
}

Status StereoGrabber::GrabByTime(StereoFrame* pair) {
  int drops = 0;
  for (;;) {
    if (!pending_left_) {
      Frame f;
      Status s = left_->Grab(&f);
      if (!s.ok()) return s;
      pending_left_ = std::move(f);
    }
    if (!pending_right_) {
      Frame f;
      Status s = right_->Grab(&f);
      if (!s.ok()) return s;
      pending_right_ = std::move(f);
    }
    const double dt = pending_left_->timestamp_s - pending_right_->timestamp_s;
    if (std::abs(dt) <= options_.tolerance_s) {
      pair->left = std::move(*pending_left_);
      pair->right = std::move(*pending_right_);
      pending_left_.reset();
      pending_right_.reset();
      return Status::Ok();
    }
    // The earlier frame's partner, if any, has been missed: drop it.
    if (dt < 0) {
      pending_left_.reset();
      ++dropped_left_;
    } else {
      pending_right_.reset();
      ++dropped_right_;
    }
    if (++drops >= options_.max_consecutive_drops) {
      std::ostringstream os;
      os << "no left/right pair within " << options_.tolerance_s * 1e3
         << " ms after " << drops << " frames in a row (last difference "
         << dt * 1e3 << " ms): do the cameras run at the same frame rate?";
      return Status::Error(Status::Kind::kIoError, os.str());
    }
  }
}

}  // namespace kincal::capture
