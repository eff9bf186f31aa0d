// Replay of a recorded video file through cv::VideoCapture (whatever codecs
// the installed OpenCV videoio backends decode).

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "capture/frame_source.h"

namespace kincal::capture {
namespace {

class VideoSource : public FrameSource {
 public:
  explicit VideoSource(const SourceUri& uri) : path_(uri.path) {}

  Status Open() override {
    struct stat st {};
    if (::stat(path_.c_str(), &st) != 0) {
      const int err = errno;
      return Status::Error(KindFromErrno(err), "video source '" + path_ +
                                                   "': " + std::strerror(err));
    }
    if (!capture_.open(path_, cv::CAP_ANY) || !capture_.isOpened()) {
      return Status::Error(
          Status::Kind::kUnsupported,
          "video source '" + path_ + "': no OpenCV backend can decode it");
    }
    fps_ = capture_.get(cv::CAP_PROP_FPS);
    if (!(fps_ > 0 && fps_ < 1e6)) fps_ = 0;
    next_ = 0;
    return Status::Ok();
  }

  Status Grab(Frame* frame) override {
    if (!capture_.isOpened()) {
      return Status::Error(Status::Kind::kIoError,
                           "video source '" + path_ + "': not open");
    }
    cv::Mat image;
    if (!capture_.read(image) || image.empty()) {
      return Status::Error(Status::Kind::kEndOfStream,
                           "video source '" + path_ + "': end after " +
                               std::to_string(next_) + " frames");
    }
    if (image.depth() != CV_8U ||
        (image.channels() != 1 && image.channels() != 3)) {
      return Status::Error(
          Status::Kind::kUnsupported,
          "video source '" + path_ + "': frames are not 8-bit gray or BGR");
    }
    frame->image = image;
    frame->sequence = next_;
    // Media time from the container frame rate (frame index when unknown).
    frame->timestamp_s = fps_ > 0 ? next_ / fps_ : static_cast<double>(next_);
    ++next_;
    return Status::Ok();
  }

  Status Close() override {
    capture_.release();
    return Status::Ok();
  }

  std::string Describe() const override {
    std::ostringstream os;
    os << "video " << path_;
    if (fps_ > 0) os << " at " << fps_ << " fps";
    if (capture_.isOpened()) os << " (" << capture_.getBackendName() << ")";
    return os.str();
  }
  bool IsLive() const override { return false; }
  TimeBase time_base() const override { return TimeBase::kMedia; }

 private:
  std::string path_;
  cv::VideoCapture capture_;
  double fps_ = 0;
  int64_t next_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> MakeVideoSource(const SourceUri& uri) {
  return std::make_unique<VideoSource>(uri);
}

}  // namespace kincal::capture
