#include "capture/frame_grabber.h"

#include <algorithm>
#include <sstream>
#include <utility>

namespace kincal::capture {

const char* PairingName(FrameGrabberOptions::Pairing pairing) {
  switch (pairing) {
    case FrameGrabberOptions::Pairing::kAuto:
      return "auto";
    case FrameGrabberOptions::Pairing::kLockStep:
      return "lockstep";
    case FrameGrabberOptions::Pairing::kNearestTimestamp:
      return "timestamp";
  }
  return "?";
}

const char* FrameSetNoun(size_t cameras) {
  return cameras == 1 ? "frames" : cameras == 2 ? "pairs" : "frame sets";
}

FrameGrabber::FrameGrabber(std::vector<FrameSource*> sources,
                           FrameGrabberOptions options)
    : sources_(std::move(sources)),
      options_(options),
      pairing_(options.pairing),
      pending_(sources_.size()),
      dropped_(sources_.size(), 0) {
  if (pairing_ == Pairing::kAuto) {
    const bool any_live =
        std::any_of(sources_.begin(), sources_.end(),
                    [](const FrameSource* s) { return s->IsLive(); });
    pairing_ = any_live ? Pairing::kNearestTimestamp : Pairing::kLockStep;
  }
}

FrameGrabber::~FrameGrabber() { Close(); }

Status FrameGrabber::Open() {
  if (sources_.empty()) {
    return Status::Error(Status::Kind::kUnsupported,
                         "frame grabber: no camera given");
  }
  if (pairing_ == Pairing::kNearestTimestamp) {
    for (size_t k = 1; k < sources_.size(); ++k) {
      if (sources_[k]->time_base() == sources_[0]->time_base()) continue;
      return Status::Error(Status::Kind::kUnsupported,
                           "cannot pair by time: " + sources_[0]->Describe() +
                               " runs on " +
                               TimeBaseName(sources_[0]->time_base()) +
                               " time, " + sources_[k]->Describe() + " on " +
                               TimeBaseName(sources_[k]->time_base()) +
                               " time; use only cameras or only recordings");
    }
  }
  for (size_t k = 0; k < sources_.size(); ++k) {
    const Status s = sources_[k]->Open();
    if (s.ok()) continue;
    for (size_t j = 0; j < k; ++j) sources_[j]->Close();
    return s;
  }
  open_ = true;
  return Status::Ok();
}

Status FrameGrabber::Close() {
  if (!open_) return Status::Ok();
  open_ = false;
  Status first;
  for (size_t k = 0; k < sources_.size(); ++k) {
    pending_[k].reset();
    const Status s = sources_[k]->Close();
    if (first.ok()) first = s;
  }
  return first;
}

Status FrameGrabber::Grab(FrameSet* set) {
  if (!open_) {
    return Status::Error(Status::Kind::kIoError, "frame grabber not open");
  }
  set->frames.resize(sources_.size());
  Status s =
      pairing_ == Pairing::kLockStep ? GrabLockStep(set) : GrabByTime(set);
  if (s.ok()) set->index = sets_++;
  return s;
}

Status FrameGrabber::GrabLockStep(FrameSet* set) {
  for (size_t k = 0; k < sources_.size(); ++k) {
    const Status s = sources_[k]->Grab(&set->frames[k]);
    if (s.ok()) continue;
    if (s.kind() != Status::Kind::kEndOfStream) return s;
    // Source k ended: the frames of this round are no set, and any source
    // after k that still has a frame ran longer.
    bool longer = k > 0;
    for (size_t j = 0; j < k; ++j) ++dropped_[j];
    for (size_t j = k + 1; j < sources_.size(); ++j) {
      Frame extra;
      if (!sources_[j]->Grab(&extra).ok()) continue;
      ++dropped_[j];
      longer = true;
    }
    if (longer) length_mismatch_ = true;
    return s;
  }
  return Status::Ok();
}

Status FrameGrabber::GrabByTime(FrameSet* set) {
  int drops = 0;
  for (;;) {
    for (size_t k = 0; k < sources_.size(); ++k) {
      if (pending_[k]) continue;
      Frame f;
      const Status s = sources_[k]->Grab(&f);
      if (!s.ok()) return s;
      pending_[k] = std::move(f);
    }
    size_t latest = 0, earliest = 0;
    for (size_t k = 1; k < sources_.size(); ++k) {
      if (pending_[k]->timestamp_s > pending_[latest]->timestamp_s) latest = k;
      if (pending_[k]->timestamp_s < pending_[earliest]->timestamp_s) {
        earliest = k;
      }
    }
    const double t_latest = pending_[latest]->timestamp_s;
    const double spread = t_latest - pending_[earliest]->timestamp_s;
    if (spread <= options_.tolerance_s) {
      for (size_t k = 0; k < sources_.size(); ++k) {
        set->frames[k] = std::move(*pending_[k]);
        pending_[k].reset();
      }
      return Status::Ok();
    }
    // Frames too early for the latest one have missed their set: drop them.
    for (size_t k = 0; k < sources_.size(); ++k) {
      if (t_latest - pending_[k]->timestamp_s <= options_.tolerance_s) continue;
      pending_[k].reset();
      ++dropped_[k];
      ++drops;
    }
    if (drops >= options_.max_consecutive_drops) {
      std::ostringstream os;
      os << "no set of " << sources_.size() << " frames within "
         << options_.tolerance_s * 1e3 << " ms after " << drops
         << " frames in a row (last difference " << spread * 1e3 << " ms, "
         << sources_[earliest]->Describe() << " behind "
         << sources_[latest]->Describe()
         << "): do the cameras run at the same frame rate?";
      return Status::Error(Status::Kind::kIoError, os.str());
    }
  }
}

}  // namespace kincal::capture
