#include "capture/pixel_convert.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <vector>

namespace kincal::capture {
namespace {

PixelBuffer Buffer(const std::vector<uint8_t>& bytes, int w, int h,
                   PixelLayout layout, int stride = 0) {
  PixelBuffer b;
  b.data = bytes.data();
  b.bytes = bytes.size();
  b.width = w;
  b.height = h;
  b.stride = stride;
  b.layout = layout;
  return b;
}

TEST(PixelConvertTest, Gray8HonoursTheRowStride) {
  // 3x2 image in rows of 5 bytes; the 2 padding bytes are 0xff.
  const std::vector<uint8_t> raw = {1, 2, 3, 255, 255, 4, 5, 6, 255, 255};
  cv::Mat out;
  ASSERT_TRUE(
      ConvertToMat(Buffer(raw, 3, 2, PixelLayout::kGray8, 5), &out).ok());
  ASSERT_EQ(out.type(), CV_8UC1);
  ASSERT_EQ(out.size(), cv::Size(3, 2));
  EXPECT_EQ(out.at<uint8_t>(0, 2), 3);
  EXPECT_EQ(out.at<uint8_t>(1, 0), 4);
  EXPECT_EQ(out.at<uint8_t>(1, 2), 6);
  EXPECT_NE(static_cast<const void*>(out.data), raw.data());  // owns a copy
}

TEST(PixelConvertTest, YuyvIsY0UY1VWithVideoRangeBt601) {
  // Macropixel 1: black then white (U = V = 128); macropixel 2: pure red
  // (Y 81, U 90, V 240 in BT.601 video range) twice.
  const std::vector<uint8_t> raw = {16, 128, 235, 128, 81, 90, 81, 240};
  cv::Mat out;
  ASSERT_TRUE(ConvertToMat(Buffer(raw, 4, 1, PixelLayout::kYuyv), &out).ok());
  ASSERT_EQ(out.type(), CV_8UC3);
  const cv::Vec3b black = out.at<cv::Vec3b>(0, 0);
  const cv::Vec3b white = out.at<cv::Vec3b>(0, 1);
  const cv::Vec3b red = out.at<cv::Vec3b>(0, 2);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LE(black[c], 3);
    EXPECT_GE(white[c], 252);
  }
  EXPECT_LE(red[0], 4);    // B
  EXPECT_LE(red[1], 4);    // G
  EXPECT_GE(red[2], 250);  // R
}

TEST(PixelConvertTest, Mono16KeepsTheTopSignificantBits) {
  // Little-endian 16-bit samples: 12-bit data 4095, 2048, 0; 16-bit 65535, 256.
  std::vector<uint8_t> raw12 = {0xff, 0x0f, 0x00, 0x08, 0x00, 0x00};
  PixelBuffer b = Buffer(raw12, 3, 1, PixelLayout::kGray16);
  b.bits = 12;
  cv::Mat out;
  ASSERT_TRUE(ConvertToMat(b, &out).ok());
  ASSERT_EQ(out.type(), CV_8UC1);
  EXPECT_EQ(out.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(out.at<uint8_t>(0, 1), 128);
  EXPECT_EQ(out.at<uint8_t>(0, 2), 0);

  std::vector<uint8_t> raw16 = {0xff, 0xff, 0x00, 0x01};
  b = Buffer(raw16, 2, 1, PixelLayout::kGray16);
  b.bits = 16;
  ASSERT_TRUE(ConvertToMat(b, &out).ok());
  EXPECT_EQ(out.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(out.at<uint8_t>(0, 1), 1);
}

// A Bayer mosaic of one colour (B, G, R) for the GenICam pattern `p`.
std::vector<uint8_t> Mosaic(BayerPattern p, int w, int h, cv::Vec3b bgr) {
  // Colour index (0 B, 1 G, 2 R) at (row % 2, col % 2).
  int cell[2][2] = {{1, 1}, {1, 1}};
  switch (p) {
    case BayerPattern::kRG:
      cell[0][0] = 2, cell[0][1] = 1, cell[1][0] = 1, cell[1][1] = 0;
      break;
    case BayerPattern::kGR:
      cell[0][0] = 1, cell[0][1] = 2, cell[1][0] = 0, cell[1][1] = 1;
      break;
    case BayerPattern::kGB:
      cell[0][0] = 1, cell[0][1] = 0, cell[1][0] = 2, cell[1][1] = 1;
      break;
    case BayerPattern::kBG:
      cell[0][0] = 0, cell[0][1] = 1, cell[1][0] = 1, cell[1][1] = 2;
      break;
  }
  std::vector<uint8_t> raw(w * h);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) raw[r * w + c] = bgr[cell[r % 2][c % 2]];
  }
  return raw;
}

TEST(PixelConvertTest, BayerPatternsFollowGenicamNaming) {
  const cv::Vec3b colour(20, 120, 220);  // B, G, R all different
  for (BayerPattern p : {BayerPattern::kRG, BayerPattern::kGR,
                         BayerPattern::kGB, BayerPattern::kBG}) {
    const std::vector<uint8_t> raw = Mosaic(p, 8, 6, colour);
    PixelBuffer b = Buffer(raw, 8, 6, PixelLayout::kBayer8);
    b.bayer = p;
    cv::Mat out;
    ASSERT_TRUE(ConvertToMat(b, &out).ok());
    ASSERT_EQ(out.type(), CV_8UC3);
    EXPECT_EQ(out.at<cv::Vec3b>(3, 4), colour) << "pattern " << int(p);

    // The same mosaic as 12-bit samples gives the same colour.
    std::vector<uint8_t> wide;
    for (uint8_t v : raw) {
      const uint16_t s = static_cast<uint16_t>(v) << 4;
      wide.push_back(s & 0xff);
      wide.push_back(s >> 8);
    }
    PixelBuffer b16 = Buffer(wide, 8, 6, PixelLayout::kBayer16);
    b16.bayer = p;
    b16.bits = 12;
    ASSERT_TRUE(ConvertToMat(b16, &out).ok());
    EXPECT_EQ(out.at<cv::Vec3b>(3, 4), colour) << "pattern " << int(p);
  }
}

TEST(PixelConvertTest, KeptMosaicIsTheRawPhotositesWithTheirPatternName) {
  const cv::Vec3b colour(20, 120, 220);
  const std::vector<uint8_t> raw = Mosaic(BayerPattern::kGB, 8, 6, colour);
  PixelBuffer b = Buffer(raw, 8, 6, PixelLayout::kBayer8);
  b.bayer = BayerPattern::kGB;
  b.keep_mosaic = true;
  cv::Mat out;
  ASSERT_TRUE(ConvertToMat(b, &out).ok());
  ASSERT_EQ(out.type(), CV_8UC1);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 8; ++c) {
      ASSERT_EQ(out.at<uint8_t>(r, c), raw[r * 8 + c]) << r << "," << c;
    }
  }
  EXPECT_NE(static_cast<const void*>(out.data), raw.data());  // owns a copy

  // 12-bit samples keep their top 8 bits, still undemosaiced.
  std::vector<uint8_t> wide;
  for (uint8_t v : raw) {
    const uint16_t s = static_cast<uint16_t>(v) << 4;
    wide.push_back(s & 0xff);
    wide.push_back(s >> 8);
  }
  PixelBuffer b16 = Buffer(wide, 8, 6, PixelLayout::kBayer16);
  b16.bits = 12;
  b16.keep_mosaic = true;
  ASSERT_TRUE(ConvertToMat(b16, &out).ok());
  ASSERT_EQ(out.type(), CV_8UC1);
  EXPECT_EQ(out.at<uint8_t>(0, 0), 120);  // G at the top-left of GBRG
  EXPECT_EQ(out.at<uint8_t>(0, 1), 20);   // B
  EXPECT_EQ(out.at<uint8_t>(1, 0), 220);  // R

  EXPECT_STREQ(MosaicName(BayerPattern::kRG), "RGGB");
  EXPECT_STREQ(MosaicName(BayerPattern::kGR), "GRBG");
  EXPECT_STREQ(MosaicName(BayerPattern::kGB), "GBRG");
  EXPECT_STREQ(MosaicName(BayerPattern::kBG), "BGGR");
}

TEST(PixelConvertTest, RgbIsSwappedToBgr) {
  const std::vector<uint8_t> raw = {200, 100, 50};
  cv::Mat out;
  ASSERT_TRUE(ConvertToMat(Buffer(raw, 1, 1, PixelLayout::kRgb8), &out).ok());
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(50, 100, 200));
}

TEST(PixelConvertTest, MjpgDecodesAndChecksItsSize) {
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(
      ".jpg", cv::Mat(16, 32, CV_8UC3, cv::Scalar(90, 90, 90)), jpeg));
  PixelBuffer b = Buffer(jpeg, 32, 16, PixelLayout::kMjpg);
  cv::Mat out;
  ASSERT_TRUE(ConvertToMat(b, &out).ok());
  EXPECT_EQ(out.size(), cv::Size(32, 16));
  EXPECT_NEAR(out.at<cv::Vec3b>(8, 8)[1], 90, 3);

  b.width = 64;  // the device said 64x16
  EXPECT_EQ(ConvertToMat(b, &out).kind(), Status::Kind::kIoError);

  std::vector<uint8_t> garbage(500, 0x55);
  EXPECT_EQ(
      ConvertToMat(Buffer(garbage, 32, 16, PixelLayout::kMjpg), &out).kind(),
      Status::Kind::kIoError);
}

TEST(PixelConvertTest, ShortOrBadBuffersAreStatuses) {
  std::vector<uint8_t> raw(4 * 3 * 2 - 1);  // one byte short of 4x3 YUYV
  cv::Mat out;
  Status s = ConvertToMat(Buffer(raw, 4, 3, PixelLayout::kYuyv), &out);
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_NE(s.message().find("short frame"), std::string::npos);
  EXPECT_EQ(ConvertToMat(Buffer(raw, 3, 2, PixelLayout::kYuyv), &out).kind(),
            Status::Kind::kUnsupported);  // odd YUYV width
  PixelBuffer b = Buffer(raw, 2, 2, PixelLayout::kGray16);
  b.bits = 20;
  EXPECT_EQ(ConvertToMat(b, &out).kind(), Status::Kind::kUnsupported);
  EXPECT_EQ(
      ConvertToMat(Buffer(raw, 4, 1, PixelLayout::kGray8, 2), &out).kind(),
      Status::Kind::kUnsupported);  // stride < row
}

TEST(PixelConvertTest, GenicamNames) {
  PixelLayout layout;
  BayerPattern bayer;
  int bits;
  ASSERT_TRUE(LayoutFromGenicamName("Mono12", &layout, &bayer, &bits));
  EXPECT_EQ(layout, PixelLayout::kGray16);
  EXPECT_EQ(bits, 12);
  ASSERT_TRUE(LayoutFromGenicamName("BayerGB8", &layout, &bayer, &bits));
  EXPECT_EQ(layout, PixelLayout::kBayer8);
  EXPECT_EQ(bayer, BayerPattern::kGB);
  ASSERT_TRUE(LayoutFromGenicamName("BayerBG16", &layout, &bayer, &bits));
  EXPECT_EQ(layout, PixelLayout::kBayer16);
  EXPECT_EQ(bayer, BayerPattern::kBG);
  EXPECT_FALSE(LayoutFromGenicamName("YUV422Packed", &layout, &bayer, &bits));
  EXPECT_FALSE(LayoutFromGenicamName("BayerXY8", &layout, &bayer, &bits));
  EXPECT_FALSE(LayoutFromGenicamName("Mono10p", &layout, &bayer, &bits));
}

}  // namespace
}  // namespace kincal::capture
