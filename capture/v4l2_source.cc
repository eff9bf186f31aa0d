// V4L2 camera source: memory-mapped streaming I/O, through libv4l2 when it
// was found (it works around quirks of many UVC cameras) or plain syscalls.

#include <fcntl.h>
#include <glob.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/select.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <sstream>
#include <vector>

#include "capture/frame_source.h"
#include "capture/pixel_convert.h"

#ifdef KINCAL_HAVE_LIBV4L2
#include <libv4l2.h>
#define KINCAL_V4L2_WRAP(fd) v4l2_fd_open(fd, 0)
#define KINCAL_V4L2_CLOSE v4l2_close
#define KINCAL_V4L2_IOCTL v4l2_ioctl
#define KINCAL_V4L2_MMAP v4l2_mmap
#define KINCAL_V4L2_MUNMAP v4l2_munmap
#else
#define KINCAL_V4L2_WRAP(fd) (fd)
#define KINCAL_V4L2_CLOSE ::close
#define KINCAL_V4L2_IOCTL ::ioctl
#define KINCAL_V4L2_MMAP ::mmap
#define KINCAL_V4L2_MUNMAP ::munmap
#endif

namespace kincal::capture {

bool HaveLibV4l2() {
#ifdef KINCAL_HAVE_LIBV4L2
  return true;
#else
  return false;
#endif
}

namespace {

// ioctl that retries when interrupted by a signal.
int Xioctl(int fd, unsigned long request, void* arg) {
  int r;
  do {
    r = KINCAL_V4L2_IOCTL(fd, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

std::string FourCc(uint32_t code) {
  std::string s;
  for (int i = 0; i < 4; ++i) s += static_cast<char>((code >> (8 * i)) & 0xff);
  return s;
}

uint32_t FourCcCode(const std::string& name) {
  if (name == "GREY") return V4L2_PIX_FMT_GREY;
  if (name == "MJPG") return V4L2_PIX_FMT_MJPEG;
  if (name == "RGGB") return V4L2_PIX_FMT_SRGGB8;
  if (name == "GRBG") return V4L2_PIX_FMT_SGRBG8;
  if (name == "GBRG") return V4L2_PIX_FMT_SGBRG8;
  if (name == "BA81") return V4L2_PIX_FMT_SBGGR8;
  return V4L2_PIX_FMT_YUYV;
}

// The 8-bit Bayer fourccs (V4L2's names for the top-left 2x2 cell; BA81 is
// BGGR); false for other formats.
bool BayerOfFourCc(const std::string& name, BayerPattern* pattern) {
  if (name == "RGGB") {
    *pattern = BayerPattern::kRG;
  } else if (name == "GRBG") {
    *pattern = BayerPattern::kGR;
  } else if (name == "GBRG") {
    *pattern = BayerPattern::kGB;
  } else if (name == "BA81") {
    *pattern = BayerPattern::kBG;
  } else {
    return false;
  }
  return true;
}

// Opens a device and checks it speaks V4L2 (VIDIOC_QUERYCAP) before handing
// it to libv4l2, so a wrong path is reported once, quietly. -1 with errno set
// (ENOTTY: not a V4L2 device).
int OpenV4l2(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return -1;
  v4l2_capability cap{};
  int r;
  do {
    r = ::ioctl(fd, VIDIOC_QUERYCAP, &cap);
  } while (r == -1 && errno == EINTR);
  if (r != 0) {
    const int err = errno;
    ::close(fd);
    errno = err;
    return -1;
  }
  const int wrapped = KINCAL_V4L2_WRAP(fd);
  if (wrapped < 0) {
    const int err = errno;
    ::close(fd);
    errno = err;
  }
  return wrapped;
}

// Pixel formats (and discrete sizes) a device offers, e.g. "YUYV 640x480".
std::vector<std::string> EnumerateFormats(int fd) {
  std::vector<std::string> out;
  v4l2_fmtdesc desc{};
  desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  for (desc.index = 0; Xioctl(fd, VIDIOC_ENUM_FMT, &desc) == 0; ++desc.index) {
    std::string entry = FourCc(desc.pixelformat);
    v4l2_frmsizeenum size{};
    size.pixel_format = desc.pixelformat;
    for (size.index = 0; Xioctl(fd, VIDIOC_ENUM_FRAMESIZES, &size) == 0;
         ++size.index) {
      if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        entry += " " + std::to_string(size.discrete.width) + "x" +
                 std::to_string(size.discrete.height);
      } else {
        entry += " " + std::to_string(size.stepwise.min_width) + "x" +
                 std::to_string(size.stepwise.min_height) + ".." +
                 std::to_string(size.stepwise.max_width) + "x" +
                 std::to_string(size.stepwise.max_height);
        break;
      }
    }
    out.push_back(entry);
  }
  return out;
}

class V4l2Source : public FrameSource {
 public:
  explicit V4l2Source(const SourceUri& uri)
      : uri_(uri),
        device_(uri.path),
        format_name_(uri.GetString("format", "YUYV")),
        width_(uri.GetInt("width", 0, 16, 16384)),
        height_(uri.GetInt("height", 0, 16, 16384)),
        fps_(uri.GetDouble("fps", 0, 0.1, 1000)),
        n_buffers_(uri.GetInt("buffers", 4, 2, 32)),
        timeout_ms_(uri.GetInt("timeout_ms", 2000, 1, 600000)),
        keep_mosaic_(KeepsMosaic(uri)) {}
  ~V4l2Source() override { Close(); }

  Status Open() override {
    if (fd_ >= 0) return Status::Ok();
    struct stat st {};
    if (::stat(device_.c_str(), &st) != 0) {
      const int err = errno;
      return Status::Error(KindFromErrno(err),
                           device_ + ": " + std::strerror(err) +
                               " (is the camera plugged in? see kincal "
                               "capture --list)");
    }
    const int fd = OpenV4l2(device_);
    if (fd < 0) {
      const int err = errno;
      if (err == ENOTTY || err == EINVAL) {
        return Status::Error(Status::Kind::kUnsupported,
                             device_ + ": not a V4L2 device");
      }
      return Status::Error(
          err == EACCES ? Status::Kind::kIoError : KindFromErrno(err),
          device_ + ": cannot open: " + std::strerror(err) +
              (err == EACCES ? " (add yourself to the 'video' group)" : ""));
    }
    fd_ = fd;
    Status s = Configure();
    if (!s.ok()) Close();
    return s;
  }

  Status Grab(Frame* frame) override {
    if (!streaming_) {
      return Status::Error(Status::Kind::kIoError, device_ + ": not open");
    }
    const double deadline = MonotonicSeconds() + 1e-3 * timeout_ms_;
    for (;;) {
      const double left = deadline - MonotonicSeconds();
      if (left <= 0) break;
      fd_set fds;
      FD_ZERO(&fds);
      FD_SET(fd_, &fds);
      timeval tv{};
      tv.tv_sec = static_cast<time_t>(left);
      tv.tv_usec = static_cast<suseconds_t>((left - tv.tv_sec) * 1e6);
      const int r = ::select(fd_ + 1, &fds, nullptr, nullptr, &tv);
      if (r < 0) {
        if (errno == EINTR) continue;
        return Errno("select");
      }
      if (r == 0) break;
      v4l2_buffer buf{};
      buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      buf.memory = V4L2_MEMORY_MMAP;
      if (Xioctl(fd_, VIDIOC_DQBUF, &buf) != 0) {
        if (errno == EAGAIN) continue;
        // ENODEV: unplugged while streaming.
        return Errno("VIDIOC_DQBUF");
      }
      Status s = Convert(buf, frame);
      if (Xioctl(fd_, VIDIOC_QBUF, &buf) != 0 && s.ok()) {
        s = Errno("VIDIOC_QBUF");
      }
      return s;
    }
    return Status::Error(
        Status::Kind::kTimeout,
        device_ + ": no frame within " + std::to_string(timeout_ms_) + " ms");
  }

  Status Close() override {
    if (fd_ < 0) return Status::Ok();
    if (streaming_) {
      v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      Xioctl(fd_, VIDIOC_STREAMOFF, &type);
      streaming_ = false;
    }
    for (const Mapping& m : maps_) KINCAL_V4L2_MUNMAP(m.start, m.length);
    maps_.clear();
    v4l2_requestbuffers req{};
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    Xioctl(fd_, VIDIOC_REQBUFS, &req);  // count 0 frees the buffers
    KINCAL_V4L2_CLOSE(fd_);
    fd_ = -1;
    return Status::Ok();
  }

  std::string Describe() const override {
    std::ostringstream os;
    os << "v4l2 " << device_;
    if (!card_.empty()) os << " (" << card_ << ")";
    os << " " << format_name_;
    if (width_ > 0) os << " " << width_ << "x" << height_;
    if (fps_ > 0) os << " " << fps_ << " fps";
    if (!mosaic().empty()) os << ", raw mosaic";
    return os.str();
  }
  bool IsLive() const override { return true; }
  std::string mosaic() const override {
    BayerPattern p;
    return keep_mosaic_ && BayerOfFourCc(format_name_, &p) ? MosaicName(p) : "";
  }
  TimeBase time_base() const override { return TimeBase::kHostMonotonic; }

 private:
  struct Mapping {
    void* start = nullptr;
    size_t length = 0;
  };

  // A failed ioctl/syscall: ENODEV (unplugged) is kNotFound, EBUSY kBusy
  // (another program streams from the camera), anything else kIoError.
  Status Errno(const std::string& what) const {
    const int err = errno;
    const Status::Kind kind = err == ENODEV  ? Status::Kind::kNotFound
                              : err == EBUSY ? Status::Kind::kBusy
                                             : Status::Kind::kIoError;
    return Status::Error(kind,
                         device_ + ": " + what + ": " + std::strerror(err));
  }

  Status Configure() {
    v4l2_capability cap{};
    if (Xioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0) {
      return Status::Error(
          Status::Kind::kUnsupported,
          device_ + ": not a V4L2 device (" + std::strerror(errno) + ")");
    }
    card_ = reinterpret_cast<const char*>(cap.card);
    const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS)
                              ? cap.device_caps
                              : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING)) {
      return Status::Error(Status::Kind::kUnsupported,
                           device_ + " (" + card_ +
                               "): no video capture with streaming I/O (a "
                               "metadata node? try the next /dev/video)");
    }
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (Xioctl(fd_, VIDIOC_G_FMT, &fmt) != 0) return Errno("VIDIOC_G_FMT");
    const uint32_t want = FourCcCode(format_name_);
    fmt.fmt.pix.pixelformat = want;
    if (width_ > 0) {
      fmt.fmt.pix.width = width_;
      fmt.fmt.pix.height = height_;
    }
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (Xioctl(fd_, VIDIOC_S_FMT, &fmt) != 0) return Errno("VIDIOC_S_FMT");
    if (fmt.fmt.pix.pixelformat != want) {
      std::string offered;
      for (const std::string& f : EnumerateFormats(fd_)) offered += "; " + f;
      return Status::Error(Status::Kind::kUnsupported,
                           device_ + ": format " + format_name_ +
                               " not offered (device chose " +
                               FourCc(fmt.fmt.pix.pixelformat) +
                               "); it offers" + offered.substr(1));
    }
    if (width_ > 0 && (static_cast<int>(fmt.fmt.pix.width) != width_ ||
                       static_cast<int>(fmt.fmt.pix.height) != height_)) {
      return Status::Error(Status::Kind::kUnsupported,
                           device_ + ": " + std::to_string(width_) + "x" +
                               std::to_string(height_) + " not offered for " +
                               format_name_ + " (nearest " +
                               std::to_string(fmt.fmt.pix.width) + "x" +
                               std::to_string(fmt.fmt.pix.height) + ")");
    }
    width_ = fmt.fmt.pix.width;
    height_ = fmt.fmt.pix.height;
    stride_ = fmt.fmt.pix.bytesperline;
    if (fps_ > 0) {
      v4l2_streamparm parm{};
      parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      parm.parm.capture.timeperframe.numerator = 1000;
      parm.parm.capture.timeperframe.denominator =
          static_cast<uint32_t>(std::lround(fps_ * 1000));
      if (Xioctl(fd_, VIDIOC_S_PARM, &parm) != 0) {
        return Errno("VIDIOC_S_PARM (fps)");
      }
      const auto& tpf = parm.parm.capture.timeperframe;
      if (tpf.numerator > 0) fps_ = double(tpf.denominator) / tpf.numerator;
    }
    v4l2_requestbuffers req{};
    req.count = n_buffers_;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (Xioctl(fd_, VIDIOC_REQBUFS, &req) != 0) return Errno("VIDIOC_REQBUFS");
    if (req.count < 2) {
      return Status::Error(Status::Kind::kIoError,
                           device_ + ": driver granted only " +
                               std::to_string(req.count) + " buffers");
    }
    for (uint32_t i = 0; i < req.count; ++i) {
      v4l2_buffer buf{};
      buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      buf.memory = V4L2_MEMORY_MMAP;
      buf.index = i;
      if (Xioctl(fd_, VIDIOC_QUERYBUF, &buf) != 0) {
        return Errno("VIDIOC_QUERYBUF");
      }
      Mapping m;
      m.length = buf.length;
      m.start = KINCAL_V4L2_MMAP(nullptr, buf.length, PROT_READ | PROT_WRITE,
                                 MAP_SHARED, fd_, buf.m.offset);
      if (m.start == MAP_FAILED) return Errno("mmap");
      maps_.push_back(m);
      if (Xioctl(fd_, VIDIOC_QBUF, &buf) != 0) return Errno("VIDIOC_QBUF");
    }
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (Xioctl(fd_, VIDIOC_STREAMON, &type) != 0) {
      return Errno("VIDIOC_STREAMON");
    }
    streaming_ = true;
    return Status::Ok();
  }

  Status Convert(const v4l2_buffer& buf, Frame* frame) const {
    if (buf.index >= maps_.size()) {
      return Status::Error(Status::Kind::kIoError,
                           device_ + ": driver returned buffer index " +
                               std::to_string(buf.index));
    }
    if (buf.flags & V4L2_BUF_FLAG_ERROR) {
      return Status::Error(Status::Kind::kIoError,
                           device_ + ": corrupt frame " +
                               std::to_string(buf.sequence) +
                               " (driver flagged an error)");
    }
    PixelBuffer pixels;
    pixels.data = maps_[buf.index].start;
    pixels.bytes = std::min<size_t>(buf.bytesused, maps_[buf.index].length);
    pixels.width = width_;
    pixels.height = height_;
    pixels.stride = static_cast<int>(stride_);
    pixels.layout = format_name_ == "GREY"   ? PixelLayout::kGray8
                    : format_name_ == "MJPG" ? PixelLayout::kMjpg
                                             : PixelLayout::kYuyv;
    if (BayerOfFourCc(format_name_, &pixels.bayer)) {
      pixels.layout = PixelLayout::kBayer8;
      pixels.keep_mosaic = keep_mosaic_;
    }
    Status s = ConvertToMat(pixels, &frame->image);
    if (!s.ok()) {
      return Status::Error(s.kind(), device_ + ": frame " +
                                         std::to_string(buf.sequence) + ": " +
                                         s.message());
    }
    const bool monotonic = (buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) ==
                           V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    frame->timestamp_s =
        monotonic ? buf.timestamp.tv_sec + 1e-6 * buf.timestamp.tv_usec
                  : MonotonicSeconds();
    frame->sequence = buf.sequence;
    return Status::Ok();
  }

  SourceUri uri_;
  std::string device_;
  std::string format_name_;
  int width_;
  int height_;
  double fps_;
  int n_buffers_;
  int timeout_ms_;
  bool keep_mosaic_;  // bayer=raw
  uint32_t stride_ = 0;
  std::string card_;
  int fd_ = -1;
  bool streaming_ = false;
  std::vector<Mapping> maps_;
};

}  // namespace

std::unique_ptr<FrameSource> MakeV4l2Source(const SourceUri& uri) {
  return std::make_unique<V4l2Source>(uri);
}

std::vector<CameraInfo> ListV4l2Devices() {
  std::vector<CameraInfo> out;
  glob_t g{};
  std::vector<std::string> paths;
  if (::glob("/dev/video*", 0, nullptr, &g) == 0) {
    for (size_t i = 0; i < g.gl_pathc; ++i) paths.push_back(g.gl_pathv[i]);
  }
  ::globfree(&g);
  // /dev/video2 before /dev/video10.
  std::sort(paths.begin(), paths.end(), [](const auto& a, const auto& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;
  });
  for (const std::string& path : paths) {
    CameraInfo info;
    info.uri = "v4l2:" + path;
    const int fd = OpenV4l2(path);
    if (fd < 0) {
      if (errno == ENOTTY) continue;  // not a V4L2 node
      info.description = std::string("cannot open: ") + std::strerror(errno);
      out.push_back(info);
      continue;
    }
    v4l2_capability cap{};
    if (Xioctl(fd, VIDIOC_QUERYCAP, &cap) == 0) {
      const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS)
                                ? cap.device_caps
                                : cap.capabilities;
      if ((caps & V4L2_CAP_VIDEO_CAPTURE) && (caps & V4L2_CAP_STREAMING)) {
        info.description = std::string(reinterpret_cast<char*>(cap.card)) +
                           " [" + reinterpret_cast<char*>(cap.driver) + ", " +
                           reinterpret_cast<char*>(cap.bus_info) + "]";
        info.formats = EnumerateFormats(fd);
        out.push_back(info);
      }
    }
    KINCAL_V4L2_CLOSE(fd);
  }
  return out;
}

}  // namespace kincal::capture
