#ifndef KINCAL_CAPTURE_PIXEL_CONVERT_H_
#define KINCAL_CAPTURE_PIXEL_CONVERT_H_

#include <cstddef>
#include <opencv2/core.hpp>
#include <string>

#include "capture/status.h"

namespace kincal::capture {

// Raw pixel layouts delivered by V4L2 and GenICam cameras.
enum class PixelLayout {
  kGray8,    // V4L2 GREY, GenICam Mono8
  kGray16,   // GenICam Mono10/12/16 (unpacked, little-endian, `bits` used)
  kYuyv,     // V4L2 YUYV (YUV 4:2:2, Y0 U Y1 V)
  kMjpg,     // V4L2 MJPG: one JPEG per frame (`bytes` = its length)
  kBayer8,   // GenICam Bayer??8, `bayer` says which
  kBayer16,  // GenICam Bayer??10/12/16 unpacked, `bits` used
  kRgb8,     // GenICam RGB8 (R G B)
  kBgr8,     // GenICam BGR8
};

// Colour of the top-left 2x2 cell, read row by row (GenICam naming: BayerRG
// = R G / G B).
enum class BayerPattern { kRG, kGR, kGB, kBG };

// A camera buffer, not owned.
struct PixelBuffer {
  const void* data = nullptr;
  size_t bytes = 0;  // valid bytes in data
  int width = 0;
  int height = 0;
  int stride = 0;  // bytes per row; 0 = tightly packed
  PixelLayout layout = PixelLayout::kGray8;
  BayerPattern bayer = BayerPattern::kRG;
  int bits = 16;  // significant bits of 16-bit layouts (10, 12 or 16)
  // Bayer layouts: keep the raw mosaic (CV_8UC1, one photosite per pixel)
  // instead of demosaicing to BGR. The mosaic corners more accurately than
  // a demosaiced image (`track`/`bundle --bayer`, docs/VISION.md).
  bool keep_mosaic = false;
};

// The pattern's name as `track --bayer` and session.yaml's `mosaic` spell
// it, the top-left 2x2 cell row by row: RGGB, GRBG, GBRG, BGGR.
const char* MosaicName(BayerPattern pattern);

// Converts a buffer to an 8-bit image that owns its data: CV_8UC1 for gray
// layouts and kept mosaics, CV_8UC3 BGR for colour ones. 16-bit data keeps its
// top 8 significant bits (value / 2^(bits - 8), rounded, saturated). kIoError
// for a short or corrupt buffer (a truncated frame, an undecodable JPEG),
// kUnsupported for nonsensical parameters.
Status ConvertToMat(const PixelBuffer& buffer, cv::Mat* out);

// Parses GenICam pixel format names used in URIs ("Mono8", "BayerRG16", ...)
// into layout/pattern/bits; false for names kincal does not convert.
bool LayoutFromGenicamName(const std::string& name, PixelLayout* layout,
                           BayerPattern* bayer, int* bits);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_PIXEL_CONVERT_H_
