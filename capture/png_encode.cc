#include "capture/png_encode.h"

#include <png.h>
#include <zlib.h>

#include <csetjmp>
#include <opencv2/imgcodecs.hpp>

namespace kincal::capture {
namespace {

struct Sink {
  std::vector<uint8_t>* out;
  std::string error;
};

void WriteData(png_structp png, png_bytep data, png_size_t size) {
  auto* sink = static_cast<Sink*>(png_get_io_ptr(png));
  sink->out->insert(sink->out->end(), data, data + size);
}
void Flush(png_structp) {}
void OnError(png_structp png, png_const_charp message) {
  auto* sink = static_cast<Sink*>(png_get_error_ptr(png));
  sink->error = message;
  png_longjmp(png, 1);
}
void OnWarning(png_structp, png_const_charp) {}

// libpng reports errors by longjmp: keep this frame free of objects with
// destructors.
bool EncodeWithLibpng(const cv::Mat& image, int level, Sink* sink) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, sink, OnError, OnWarning);
  if (png == nullptr) {
    sink->error = "libpng: out of memory";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    if (sink->error.empty()) sink->error = "libpng: out of memory";
    return false;
  }
  png_set_write_fn(png, sink, WriteData, Flush);
  png_set_compression_level(png, level);
  png_set_filter(png, PNG_FILTER_TYPE_BASE,
                 level == 0 ? PNG_FILTER_NONE : PNG_FILTER_SUB);
  png_set_compression_strategy(png, level == 0 ? Z_DEFAULT_STRATEGY : Z_RLE);
  const bool color = image.channels() == 3;
  png_set_IHDR(png, info, image.cols, image.rows, 8,
               color ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (color) png_set_bgr(png);
  for (int r = 0; r < image.rows; ++r) {
    png_write_row(png, const_cast<png_bytep>(image.ptr<uint8_t>(r)));
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

bool EncodePng(const cv::Mat& image, int level, std::vector<uint8_t>* out,
               std::string* error) {
  out->clear();
  if (image.empty()) {
    *error = "empty image";
    return false;
  }
  if (level < 0 || level > 9) {
    *error = "PNG compression level must be 0..9";
    return false;
  }
  if (image.depth() == CV_8U &&
      (image.channels() == 1 || image.channels() == 3)) {
    out->reserve(image.total() * image.channels() + image.rows * 8 + 1024);
    Sink sink{out, {}};
    if (EncodeWithLibpng(image, level, &sink)) return true;
    *error = sink.error;
    return false;
  }
  try {
    if (cv::imencode(".png", image, *out,
                     {cv::IMWRITE_PNG_COMPRESSION, level})) {
      return true;
    }
    *error = "cannot encode a non-8/16-bit image as PNG";
  } catch (const cv::Exception& e) {
    *error = e.what();
  }
  return false;
}

}  // namespace kincal::capture
