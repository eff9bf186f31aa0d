#ifndef KINCAL_CAPTURE_PNG_ENCODE_H_
#define KINCAL_CAPTURE_PNG_ENCODE_H_

// Fast lossless PNG encoding for recording at camera rate, through libpng
// with a fixed filter and zlib strategy instead of libpng's adaptive filter
// search (which is what makes cv::imencode slow on camera frames):
//   level 0:    no filter, stored deflate blocks (about 1 ms per 1280x1024
//               gray frame here; the file is the raw size);
//   level 1..9: the Sub filter and zlib's RLE strategy at that level
//               (about 10 ms per frame at level 1; noisy camera frames
//               shrink to about half).
// 8-bit gray and BGR images; anything else goes through cv::imencode.

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace kincal::capture {

// False (with `error`) when the image cannot be encoded.
bool EncodePng(const cv::Mat& image, int level, std::vector<uint8_t>* out,
               std::string* error);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_PNG_ENCODE_H_
