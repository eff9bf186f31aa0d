#include "capture/pixel_convert.h"

#include <cstdint>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace kincal::capture {
namespace {

int BytesPerPixel(PixelLayout layout) {
  switch (layout) {
    case PixelLayout::kGray8:
    case PixelLayout::kBayer8:
      return 1;
    case PixelLayout::kGray16:
    case PixelLayout::kBayer16:
    case PixelLayout::kYuyv:
      return 2;
    case PixelLayout::kRgb8:
    case PixelLayout::kBgr8:
      return 3;
    case PixelLayout::kMjpg:
      return 0;
  }
  return 0;
}

// OpenCV names Bayer codes after the pattern seen from the second row and
// column, so GenICam "RG" (R at the top-left) is OpenCV's "BG".
int OpenCvBayerCode(BayerPattern p) {
  switch (p) {
    case BayerPattern::kRG:
      return cv::COLOR_BayerBG2BGR;
    case BayerPattern::kGR:
      return cv::COLOR_BayerGB2BGR;
    case BayerPattern::kGB:
      return cv::COLOR_BayerGR2BGR;
    case BayerPattern::kBG:
      return cv::COLOR_BayerRG2BGR;
  }
  return cv::COLOR_BayerBG2BGR;
}

// 16-bit little-endian samples with `bits` significant bits -> 8 bit.
cv::Mat To8Bit(const cv::Mat& wide, int bits) {
  cv::Mat narrow;
  wide.convertTo(narrow, CV_8U, 1.0 / static_cast<double>(1 << (bits - 8)));
  return narrow;
}

}  // namespace

Status ConvertToMat(const PixelBuffer& b, cv::Mat* out) {
  if (b.data == nullptr) {
    return Status::Error(Status::Kind::kIoError, "empty buffer");
  }
  if (b.layout == PixelLayout::kMjpg) {
    if (b.bytes < 4) {
      return Status::Error(Status::Kind::kIoError, "empty JPEG frame");
    }
    const cv::Mat encoded(1, static_cast<int>(b.bytes), CV_8UC1,
                          const_cast<void*>(b.data));
    cv::Mat decoded = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
    if (decoded.empty() || decoded.depth() != CV_8U) {
      return Status::Error(
          Status::Kind::kIoError,
          "corrupt JPEG frame (" + std::to_string(b.bytes) + " bytes)");
    }
    if (b.width > 0 && (decoded.cols != b.width || decoded.rows != b.height)) {
      return Status::Error(Status::Kind::kIoError,
                           "JPEG frame is " + std::to_string(decoded.cols) +
                               "x" + std::to_string(decoded.rows) +
                               ", expected " + std::to_string(b.width) + "x" +
                               std::to_string(b.height));
    }
    if (decoded.channels() == 4) {
      cv::cvtColor(decoded, decoded, cv::COLOR_BGRA2BGR);
    }
    *out = decoded;
    return Status::Ok();
  }
  if (b.width <= 0 || b.height <= 0 ||
      (b.layout == PixelLayout::kYuyv && b.width % 2 != 0) ||
      ((b.layout == PixelLayout::kBayer8 ||
        b.layout == PixelLayout::kBayer16) &&
       (b.width < 2 || b.height < 2))) {
    return Status::Error(Status::Kind::kUnsupported,
                         "bad image size " + std::to_string(b.width) + "x" +
                             std::to_string(b.height));
  }
  const bool wide =
      b.layout == PixelLayout::kGray16 || b.layout == PixelLayout::kBayer16;
  if (wide && (b.bits < 9 || b.bits > 16)) {
    return Status::Error(Status::Kind::kUnsupported,
                         "bad bit depth " + std::to_string(b.bits));
  }
  const size_t row_bytes =
      static_cast<size_t>(b.width) * BytesPerPixel(b.layout);
  const size_t stride =
      b.stride > 0 ? static_cast<size_t>(b.stride) : row_bytes;
  if (stride < row_bytes) {
    return Status::Error(Status::Kind::kUnsupported,
                         "stride " + std::to_string(stride) +
                             " shorter than a row of " +
                             std::to_string(row_bytes) + " bytes");
  }
  const size_t need = stride * (b.height - 1) + row_bytes;
  if (b.bytes < need) {
    return Status::Error(Status::Kind::kIoError,
                         "short frame: " + std::to_string(b.bytes) +
                             " bytes, expected " + std::to_string(need));
  }
  void* data = const_cast<void*>(b.data);
  switch (b.layout) {
    case PixelLayout::kGray8:
      *out = cv::Mat(b.height, b.width, CV_8UC1, data, stride).clone();
      break;
    case PixelLayout::kGray16:
      *out = To8Bit(cv::Mat(b.height, b.width, CV_16UC1, data, stride), b.bits);
      break;
    case PixelLayout::kYuyv:
      cv::cvtColor(cv::Mat(b.height, b.width, CV_8UC2, data, stride), *out,
                   cv::COLOR_YUV2BGR_YUY2);
      break;
    case PixelLayout::kBayer8:
    case PixelLayout::kBayer16: {
      cv::Mat mosaic =
          b.layout == PixelLayout::kBayer8
              ? cv::Mat(b.height, b.width, CV_8UC1, data, stride)
              : To8Bit(cv::Mat(b.height, b.width, CV_16UC1, data, stride),
                       b.bits);
      if (b.keep_mosaic) {
        *out = b.layout == PixelLayout::kBayer8 ? mosaic.clone() : mosaic;
      } else {
        cv::cvtColor(mosaic, *out, OpenCvBayerCode(b.bayer));
      }
      break;
    }
    case PixelLayout::kRgb8:
      cv::cvtColor(cv::Mat(b.height, b.width, CV_8UC3, data, stride), *out,
                   cv::COLOR_RGB2BGR);
      break;
    case PixelLayout::kBgr8:
      *out = cv::Mat(b.height, b.width, CV_8UC3, data, stride).clone();
      break;
    case PixelLayout::kMjpg:
      break;  // handled above
  }
  return Status::Ok();
}

const char* MosaicName(BayerPattern pattern) {
  switch (pattern) {
    case BayerPattern::kRG:
      return "RGGB";
    case BayerPattern::kGR:
      return "GRBG";
    case BayerPattern::kGB:
      return "GBRG";
    case BayerPattern::kBG:
      return "BGGR";
  }
  return "RGGB";
}

bool LayoutFromGenicamName(const std::string& name, PixelLayout* layout,
                           BayerPattern* bayer, int* bits) {
  *bits = 16;
  *bayer = BayerPattern::kRG;
  if (name == "Mono8") {
    *layout = PixelLayout::kGray8;
    return true;
  }
  if (name == "Mono10" || name == "Mono12" || name == "Mono16") {
    *layout = PixelLayout::kGray16;
    *bits = std::stoi(name.substr(4));
    return true;
  }
  if (name == "RGB8") {
    *layout = PixelLayout::kRgb8;
    return true;
  }
  if (name == "BGR8") {
    *layout = PixelLayout::kBgr8;
    return true;
  }
  if (name.size() >= 8 && name.compare(0, 5, "Bayer") == 0) {
    const std::string pattern = name.substr(5, 2);
    const std::string depth = name.substr(7);
    if (pattern == "RG") {
      *bayer = BayerPattern::kRG;
    } else if (pattern == "GR") {
      *bayer = BayerPattern::kGR;
    } else if (pattern == "GB") {
      *bayer = BayerPattern::kGB;
    } else if (pattern == "BG") {
      *bayer = BayerPattern::kBG;
    } else {
      return false;
    }
    if (depth == "8") {
      *layout = PixelLayout::kBayer8;
      return true;
    }
    if (depth == "10" || depth == "12" || depth == "16") {
      *layout = PixelLayout::kBayer16;
      *bits = std::stoi(depth);
      return true;
    }
  }
  return false;
}

}  // namespace kincal::capture
