// Replay of an image sequence: files matching a glob (or all images in a
// folder), sorted by name, exactly as `kincal track --left GLOB` reads them.

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <vector>

#include "capture/frame_source.h"
#include "data/glob.h"

namespace kincal::capture {
namespace {

bool IsImageName(const std::string& path) {
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos) return false;
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(c));
  return ext == "png" || ext == "jpg" || ext == "jpeg" || ext == "bmp" ||
         ext == "tif" || ext == "tiff" || ext == "pgm" || ext == "ppm";
}

class FolderSource : public FrameSource {
 public:
  explicit FolderSource(const SourceUri& uri)
      : pattern_(uri.path),
        fps_(uri.GetDouble("fps", 30, 0.001, 1e6)),
        mosaic_(DeclaredMosaic(uri)) {}

  Status Open() override {
    files_.clear();
    next_ = 0;
    std::string pattern = pattern_;
    struct stat st {};
    const bool is_dir =
        ::stat(pattern_.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
    if (is_dir) pattern = pattern_ + "/*";
    for (const std::string& f : GlobSorted(pattern)) {  // as kincal track
      if (!is_dir || IsImageName(f)) files_.push_back(f);
    }
    if (files_.empty()) {
      return Status::Error(Status::Kind::kNotFound,
                           "folder source '" + pattern + "': no file matches");
    }
    open_ = true;
    return Status::Ok();
  }

  Status Grab(Frame* frame) override {
    if (!open_) {
      return Status::Error(Status::Kind::kIoError,
                           "folder source '" + pattern_ + "': not open");
    }
    if (next_ >= files_.size()) {
      return Status::Error(Status::Kind::kEndOfStream,
                           "folder source '" + pattern_ + "': all " +
                               std::to_string(files_.size()) + " images read");
    }
    const std::string& path = files_[next_];
    // ANYCOLOR keeps gray images gray; 16-bit files come back as 8 bit.
    cv::Mat image = cv::imread(path, cv::IMREAD_ANYCOLOR);
    if (image.empty()) {
      return Status::Error(Status::Kind::kIoError,
                           path + ": cannot read the image");
    }
    if (!mosaic_.empty() && image.channels() != 1) {
      return Status::Error(Status::Kind::kIoError,
                           path + ": a colour image, but the source says " +
                               "mosaic=" + mosaic_ +
                               " (a raw mosaic is one gray channel; drop "
                               "mosaic= for demosaiced images)");
    }
    frame->image = image;
    frame->sequence = static_cast<int64_t>(next_);
    frame->timestamp_s = static_cast<double>(next_) / fps_;
    ++next_;
    return Status::Ok();
  }

  Status Close() override {
    open_ = false;
    return Status::Ok();
  }

  std::string Describe() const override {
    std::ostringstream os;
    os << "folder " << pattern_;
    if (open_) os << " (" << files_.size() << " images)";
    os << " at " << fps_ << " fps";
    if (!mosaic_.empty()) os << ", raw " << mosaic_ << " mosaics";
    return os.str();
  }
  bool IsLive() const override { return false; }
  TimeBase time_base() const override { return TimeBase::kMedia; }
  std::string mosaic() const override { return mosaic_; }

 private:
  std::string pattern_;
  double fps_;
  std::string mosaic_;
  std::vector<std::string> files_;
  size_t next_ = 0;
  bool open_ = false;
};

}  // namespace

std::unique_ptr<FrameSource> MakeFolderSource(const SourceUri& uri) {
  return std::make_unique<FolderSource>(uri);
}

}  // namespace kincal::capture
