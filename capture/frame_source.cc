#include "capture/frame_source.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <set>
#include <sstream>

#include "data/error.h"
#include "data/session.h"

namespace kincal::capture {
namespace {

const std::map<std::string, std::set<std::string>>& AllowedKeys() {
  static const auto* keys = new std::map<std::string, std::set<std::string>>{
      {"v4l2",
       {"width", "height", "fps", "format", "buffers", "timeout_ms", "bayer"}},
      {"aravis",
       {"exposure_us", "gain", "fps", "format", "buffers", "timeout_ms",
        "bayer"}},
      {"folder", {"fps", "mosaic"}},
      {"video", {}},
      {"fake", {"width", "height", "fps", "mosaic"}},
  };
  return *keys;
}

std::string Join(const std::set<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out.empty() ? "(none)" : out;
}

[[noreturn]] void Fail(const std::string& uri, const std::string& what) {
  throw InputError("source '" + uri + "': " + what);
}

bool IsKeyChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
}

// "k=v&k2=v2" with keys [a-z0-9_]+ and no '/' (so a path is never a query).
bool LooksLikeQuery(const std::string& q) {
  if (q.empty() || q.find('/') != std::string::npos) return false;
  std::stringstream ss(q);
  std::string item;
  while (std::getline(ss, item, '&')) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0) return false;
    for (size_t i = 0; i < eq; ++i) {
      if (!IsKeyChar(item[i])) return false;
    }
  }
  return true;
}

}  // namespace

double MonotonicSeconds() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return now.tv_sec + 1e-9 * now.tv_nsec;
}

const char* TimeBaseName(TimeBase base) {
  return base == TimeBase::kHostMonotonic ? "host_monotonic" : "media";
}

Status::Kind KindFromErrno(int err) {
  switch (err) {
    case ENOENT:
    case ENODEV:
    case ENXIO:
      return Status::Kind::kNotFound;
    case EBUSY:
      return Status::Kind::kBusy;
    case ETIMEDOUT:
    case EAGAIN:
      return Status::Kind::kTimeout;
    case EINVAL:
    case ENOTTY:
    case EOPNOTSUPP:
      return Status::Kind::kUnsupported;
    default:
      return Status::Kind::kIoError;
  }
}

int SourceUri::GetInt(const std::string& key, int fallback, int min,
                      int max) const {
  auto it = params.find(key);
  if (it == params.end()) return fallback;
  const std::string& v = it->second;
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || errno != 0 || value < min || value > max) {
    Fail(text, key + "=" + v + ": expected an integer in [" +
                   std::to_string(min) + ", " + std::to_string(max) + "]");
  }
  return static_cast<int>(value);
}

double SourceUri::GetDouble(const std::string& key, double fallback, double min,
                            double max) const {
  auto it = params.find(key);
  if (it == params.end()) return fallback;
  const std::string& v = it->second;
  char* end = nullptr;
  const double value = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !std::isfinite(value) || value < min ||
      value > max) {
    std::ostringstream os;
    os << key << "=" << v << ": expected a number in [" << min << ", " << max
       << "]";
    Fail(text, os.str());
  }
  return value;
}

std::string SourceUri::GetString(const std::string& key,
                                 const std::string& fallback) const {
  auto it = params.find(key);
  return it == params.end() ? fallback : it->second;
}

bool KeepsMosaic(const SourceUri& uri) {
  const std::string b = uri.GetString("bayer", "demosaic");
  if (b != "raw" && b != "demosaic") {
    throw InputError("source '" + uri.text + "': bayer=" + b +
                     ": expected raw (keep the mosaic) or demosaic");
  }
  return b == "raw";
}

std::string DeclaredMosaic(const SourceUri& uri) {
  const std::string m = uri.GetString("mosaic", "");
  if (!m.empty() && !IsMosaicPattern(m)) {
    throw InputError("source '" + uri.text + "': mosaic=" + m +
                     ": expected RGGB, GRBG, GBRG or BGGR (the top-left 2x2 "
                     "cell row by row; GenICam BayerRG8 = RGGB)");
  }
  return m;
}

SourceUri ParseSourceUri(const std::string& text) {
  SourceUri uri;
  uri.text = text;
  const size_t colon = text.find(':');
  if (colon == std::string::npos || colon == 0) {
    Fail(text,
         "expected scheme:path with scheme v4l2, aravis, folder, video or fake "
         "(e.g. v4l2:/dev/video0, folder:/data/left*.png)");
  }
  uri.scheme = text.substr(0, colon);
  auto allowed = AllowedKeys().find(uri.scheme);
  if (allowed == AllowedKeys().end()) {
    Fail(text, "unknown scheme '" + uri.scheme +
                   "'; expected v4l2, aravis, folder, video or fake");
  }
  std::string rest = text.substr(colon + 1);
  std::string query;
  if (uri.scheme == "v4l2" || uri.scheme == "aravis" || uri.scheme == "fake") {
    const size_t q = rest.find('?');
    if (q != std::string::npos) {
      query = rest.substr(q + 1);
      rest = rest.substr(0, q);
      if (query.empty()) Fail(text, "empty query after '?'");
    }
  } else {
    // '?' is also a glob wildcard: a query only when key=value pairs follow.
    const size_t q = rest.rfind('?');
    if (q != std::string::npos && LooksLikeQuery(rest.substr(q + 1))) {
      query = rest.substr(q + 1);
      rest = rest.substr(0, q);
    }
  }
  uri.path = rest;
  if (uri.path.empty()) {
    Fail(text, uri.scheme == "aravis"
                   ? "expected a camera id after 'aravis:' (see kincal "
                     "capture --list)"
                   : "expected a path after '" + uri.scheme + ":'");
  }
  if (uri.scheme == "v4l2" && uri.path[0] != '/') {
    Fail(text, "expected an absolute device path, e.g. v4l2:/dev/video0");
  }
  if (!query.empty()) {
    std::stringstream ss(query);
    std::string item;
    while (std::getline(ss, item, '&')) {
      const size_t eq = item.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == item.size()) {
        Fail(text, "'" + item + "': expected key=value");
      }
      const std::string key = item.substr(0, eq);
      if (!allowed->second.count(key)) {
        Fail(text, "unknown setting '" + key + "' for " + uri.scheme +
                       ": expected one of " + Join(allowed->second));
      }
      if (!uri.params.emplace(key, item.substr(eq + 1)).second) {
        Fail(text, "setting '" + key + "' given twice");
      }
    }
    if (!query.empty() && query.back() == '&') {
      Fail(text, "trailing '&' in the query");
    }
  }
  // Check every value now, so a typo fails before any device is opened.
  if (uri.scheme == "v4l2") {
    uri.GetInt("width", 0, 16, 16384);
    uri.GetInt("height", 0, 16, 16384);
    if (uri.params.count("width") != uri.params.count("height")) {
      Fail(text, "give both width and height, or neither");
    }
    uri.GetDouble("fps", 0, 0.1, 1000);
    const std::string f = uri.GetString("format", "YUYV");
    static const std::set<std::string> kV4l2Formats = {
        "GREY", "YUYV", "MJPG", "RGGB", "GRBG", "GBRG", "BA81"};
    if (!kV4l2Formats.count(f)) {
      Fail(text, "format=" + f +
                     ": expected GREY, YUYV, MJPG or an 8-bit Bayer format "
                     "(RGGB, GRBG, GBRG, BA81 = BGGR)");
    }
    uri.GetInt("buffers", 4, 2, 32);
    uri.GetInt("timeout_ms", 2000, 1, 600000);
    if (KeepsMosaic(uri) && (f == "GREY" || f == "YUYV" || f == "MJPG")) {
      Fail(text,
           "bayer=raw needs a Bayer format (format=RGGB, GRBG, GBRG or "
           "BA81), got format=" +
               f);
    }
  } else if (uri.scheme == "aravis") {
    uri.GetDouble("exposure_us", 0, 1, 1e7);
    uri.GetDouble("gain", 0, 0, 100);
    uri.GetDouble("fps", 0, 0.1, 1000);
    static const std::set<std::string> kFormats = {
        "Mono8",     "Mono10",    "Mono12",   "Mono16",    "BayerRG8",
        "BayerGR8",  "BayerGB8",  "BayerBG8", "BayerRG16", "BayerGR16",
        "BayerGB16", "BayerBG16", "RGB8",     "BGR8"};
    const std::string f = uri.GetString("format", "");
    if (!f.empty() && !kFormats.count(f)) {
      Fail(text, "format=" + f + ": expected one of " + Join(kFormats));
    }
    uri.GetInt("buffers", 8, 2, 64);
    uri.GetInt("timeout_ms", 2000, 1, 600000);
    if (KeepsMosaic(uri) && !f.empty() && f.compare(0, 5, "Bayer") != 0) {
      Fail(text,
           "bayer=raw needs a Bayer format (format=BayerRG8, ...), "
           "got format=" +
               f);
    }
  } else if (uri.scheme == "folder") {
    uri.GetDouble("fps", 30, 0.001, 1e6);
    DeclaredMosaic(uri);
  } else if (uri.scheme == "fake") {
    uri.GetInt("width", 640, 16, 16384);
    uri.GetInt("height", 480, 16, 16384);
    uri.GetDouble("fps", 30, 0.1, 1000);
    DeclaredMosaic(uri);
  }
  return uri;
}

std::unique_ptr<FrameSource> MakeFrameSource(const std::string& uri) {
  return MakeFrameSource(ParseSourceUri(uri));
}

std::unique_ptr<FrameSource> MakeFrameSource(const SourceUri& uri) {
  if (uri.scheme == "v4l2") return MakeV4l2Source(uri);
  if (uri.scheme == "aravis") {
    if (!HaveAravis()) {
      Fail(uri.text,
           "this kincal was built without Aravis (install libaravis-dev and "
           "rebuild)");
    }
    return MakeAravisSource(uri);
  }
  if (uri.scheme == "folder") return MakeFolderSource(uri);
  if (uri.scheme == "video") return MakeVideoSource(uri);
  if (uri.scheme == "fake") return MakeFakeSource(uri);
  Fail(uri.text, "unknown scheme '" + uri.scheme + "'");
}

}  // namespace kincal::capture
