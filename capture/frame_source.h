#ifndef KINCAL_CAPTURE_FRAME_SOURCE_H_
#define KINCAL_CAPTURE_FRAME_SOURCE_H_

#include <cstdint>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "capture/status.h"

namespace kincal::capture {

// Which clock Frame::timestamp_s is on.
enum class TimeBase {
  // Host CLOCK_MONOTONIC, seconds (live cameras: the V4L2 buffer timestamp,
  // or Aravis' host receive time converted from CLOCK_REALTIME). Frames of
  // two live cameras are comparable, so they can be paired by time.
  kHostMonotonic,
  // Position in the recording, seconds from its start (replay sources: the
  // video position, or frame index / fps for a folder of images).
  kMedia,
};

// Now on the host's CLOCK_MONOTONIC (TimeBase::kHostMonotonic), seconds.
double MonotonicSeconds();

const char* TimeBaseName(TimeBase base);  // "host_monotonic" / "media"

// One image from one camera.
struct Frame {
  cv::Mat image;             // CV_8UC1 (gray) or CV_8UC3 (BGR); owns its data
  double timestamp_s = 0.0;  // on the source's TimeBase
  int64_t sequence = 0;      // the source's frame counter (gaps = lost frames)
};

// A camera or a recording. Not thread-safe; one thread calls Open, Grab...,
// Close. Failures are returned as Status, never thrown.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual Status Open() = 0;
  // Blocks until the next frame (or the source's timeout). kEndOfStream when a
  // replay source is exhausted.
  virtual Status Grab(Frame* frame) = 0;
  virtual Status Close() = 0;
  // Human-readable identity and settings, e.g. "v4l2 /dev/video0 1280x1024
  // YUYV 30 fps"; after Open it reports what the device actually accepted.
  virtual std::string Describe() const = 0;
  // True for cameras (frames come at their own pace, paired by timestamp),
  // false for replay (frames paired in lock step).
  virtual bool IsLive() const = 0;
  virtual TimeBase time_base() const = 0;
  // The colour filter pattern (RGGB, GRBG, GBRG or BGGR: the top-left 2x2
  // cell row by row) when the source delivers a colour sensor's raw mosaic
  // (one photosite per pixel, CV_8UC1; URI bayer=raw or mosaic=...); empty
  // for gray and demosaiced colour images. session.yaml records it, and
  // `track`/`bundle` read such images without a demosaic.
  virtual std::string mosaic() const { return {}; }
};

// A parsed source URI: "scheme:path?key=value&key=value".
struct SourceUri {
  std::string text;    // as given
  std::string scheme;  // v4l2, aravis, folder, video
  std::string path;    // device, camera id, glob or file
  std::map<std::string, std::string> params;

  // Typed access with defaults; throws InputError naming the URI when the
  // value does not parse or is out of [min, max].
  int GetInt(const std::string& key, int fallback, int min, int max) const;
  double GetDouble(const std::string& key, double fallback, double min,
                   double max) const;
  std::string GetString(const std::string& key,
                        const std::string& fallback) const;
};

// Parses and validates a source URI (scheme known, path present, only the
// scheme's keys, values well-formed). Throws kincal::InputError with a message
// naming the URI and what was expected. Touches neither devices nor files.
//
//   v4l2:/dev/video0?width=1280&height=1024&fps=30&format=GREY|YUYV|MJPG|
//        RGGB|GRBG|GBRG|BA81 (&buffers=4&timeout_ms=2000&bayer=raw|demosaic)
//   aravis:<camera id>?exposure_us=..&gain=..&fps=..&format=Mono8|Mono16|
//        BayerRG8|...&timeout_ms=2000&bayer=raw|demosaic
//   folder:/path/left*.png?fps=30      (a folder path alone: all its images)
//        (&mosaic=RGGB|GRBG|GBRG|BGGR: the images are raw mosaics)
//   video:/path/file.mp4
//
// bayer=raw keeps a Bayer format's mosaic (FrameSource::mosaic) instead of
// demosaicing it to BGR (bayer=demosaic, the default); it needs a Bayer
// format (v4l2: RGGB, GRBG, GBRG, BA81 = BGGR; aravis: Bayer??8/16).
//
// For folder: and video: a '?' is a glob wildcard unless what follows it is
// key=value pairs, so "folder:/d/img?.png" is a glob.
SourceUri ParseSourceUri(const std::string& text);

// The URI's bayer= setting: true for bayer=raw (keep a Bayer format's
// mosaic), false for bayer=demosaic or none given; InputError otherwise.
bool KeepsMosaic(const SourceUri& uri);
// The URI's mosaic= setting (folder:, fake:): the pattern of the raw mosaics
// the images hold, empty when not given; InputError for another value.
std::string DeclaredMosaic(const SourceUri& uri);

// ParseSourceUri + the matching source (not yet opened). Throws InputError on
// a bad URI, and for aravis: when kincal was built without Aravis.
std::unique_ptr<FrameSource> MakeFrameSource(const std::string& uri);
std::unique_ptr<FrameSource> MakeFrameSource(const SourceUri& uri);

// The sources, for callers that already hold a parsed URI.
std::unique_ptr<FrameSource> MakeV4l2Source(const SourceUri& uri);
std::unique_ptr<FrameSource> MakeAravisSource(const SourceUri& uri);
std::unique_ptr<FrameSource> MakeFolderSource(const SourceUri& uri);
std::unique_ptr<FrameSource> MakeVideoSource(const SourceUri& uri);
// fake:<name>?width=&height=&fps= (capture/fake_source.cc): a synthetic live
// camera for tests, benchmarks and the lab procedure without hardware.
std::unique_ptr<FrameSource> MakeFakeSource(const SourceUri& uri);

// A camera found on this machine.
struct CameraInfo {
  std::string uri;          // ready for --left/--right, e.g. "v4l2:/dev/video0"
  std::string description;  // driver/card or vendor/model/serial
  std::vector<std::string> formats;  // pixel formats and sizes when known
};

// V4L2 capture devices (/dev/video*) that support video capture + streaming.
// Empty when none; devices that cannot be opened are listed with the reason.
std::vector<CameraInfo> ListV4l2Devices();
// GigE/USB3 Vision cameras seen by Aravis; Status kUnsupported when kincal was
// built without Aravis.
Status ListAravisCameras(std::vector<CameraInfo>* cameras);
// True when kincal was built with Aravis / libv4l2.
bool HaveAravis();
bool HaveLibV4l2();

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_FRAME_SOURCE_H_
