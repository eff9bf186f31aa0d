#include "vision/target_sheet.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// The sheet's black shapes as an 8-bit image at `px_per_mm` (OpenCV pixel
// centres: page mm x lands at x * px_per_mm - 0.5), antialiased by drawing
// at 4x and averaging blocks of 4x4 pixels.
cv::Mat Rasterise(const TargetSheet& sheet, double px_per_mm) {
  const int over = 4;
  const double hi = px_per_mm * over;
  cv::Mat fine(static_cast<int>(std::round(sheet.paper.height_mm * hi)),
               static_cast<int>(std::round(sheet.paper.width_mm * hi)), CV_8UC1,
               cv::Scalar(255));
  for (const SheetRect& r : sheet.black) {
    const cv::Point a(static_cast<int>(std::lround(r.x * hi)),
                      static_cast<int>(std::lround(r.y * hi)));
    const cv::Point b(static_cast<int>(std::lround((r.x + r.width) * hi)) - 1,
                      static_cast<int>(std::lround((r.y + r.height) * hi)) - 1);
    cv::rectangle(fine, a, b, cv::Scalar(0), cv::FILLED);
  }
  cv::Mat coarse;
  cv::resize(fine, coarse, cv::Size(fine.cols / over, fine.rows / over), 0, 0,
             cv::INTER_AREA);
  return coarse;
}

// Where the sheet says target point p lands, in pixels.
Eigen::Vector2d ExpectedPixel(const TargetSheet& sheet,
                              const Eigen::Vector3d& p, double px_per_mm) {
  const Eigen::Vector2d page =
      sheet.target_origin_on_page +
      Eigen::Vector2d(p.x(), sheet.target_y_sign * p.y());
  return page * px_per_mm - Eigen::Vector2d(0.5, 0.5);
}

struct Box {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
};
Box BoundingBox(const std::vector<SheetRect>& rects) {
  Box b;
  for (const SheetRect& r : rects) {
    b.x0 = std::min(b.x0, r.x);
    b.y0 = std::min(b.y0, r.y);
    b.x1 = std::max(b.x1, r.x + r.width);
    b.y1 = std::max(b.y1, r.y + r.height);
  }
  return b;
}

TEST(TargetSheet, ChessboardSquaresAtTheSpecSize) {
  const TargetSheet sheet =
      LayoutCalibTargetSheet(ParseCalibTargetSpec("chessboard:9x6:20"), {});
  // 10 x 7 squares of 20 mm = 200 x 140 mm: wider than A4 portrait's 190 mm.
  EXPECT_TRUE(sheet.landscape);
  EXPECT_DOUBLE_EQ(sheet.paper.width_mm, 297);
  EXPECT_DOUBLE_EQ(sheet.paper.height_mm, 210);
  EXPECT_DOUBLE_EQ(sheet.board_width_mm, 200);
  EXPECT_DOUBLE_EQ(sheet.board_height_mm, 140);
  ASSERT_EQ(sheet.black.size(), 35u);  // top-left black: ceil(70 / 2)
  for (const SheetRect& r : sheet.black) {
    EXPECT_DOUBLE_EQ(r.width, 20);
    EXPECT_DOUBLE_EQ(r.height, 20);
  }
  const Box box = BoundingBox(sheet.black);
  EXPECT_NEAR(box.x1 - box.x0, 200, 1e-9);
  EXPECT_NEAR(box.y1 - box.y0, 140, 1e-9);
  EXPECT_NEAR(box.x0 + box.x1, 297, 1e-9);  // centred across the page
  EXPECT_GE(box.y0, 10);                    // inside the margin
  // The first inner corner: one square in from the top-left black square.
  EXPECT_NEAR(sheet.target_origin_on_page.x(), box.x0 + 20, 1e-9);
  EXPECT_NEAR(sheet.target_origin_on_page.y(), box.y0 + 20, 1e-9);
  // The scale bar: 11 ticks 10 mm apart after the baseline, 100 mm long.
  ASSERT_EQ(sheet.lines.size(), 12u);
  EXPECT_NEAR(sheet.lines[0].x1 - sheet.lines[0].x0, 100, 1e-9);
  EXPECT_NEAR(sheet.lines[11].x0 - sheet.lines[1].x0, 100, 1e-9);
  EXPECT_GT(sheet.lines[0].y0, box.y1);  // below the board
}

TEST(TargetSheet, PortraitWhenTheBoardFits) {
  const TargetSheet sheet =
      LayoutCalibTargetSheet(ParseCalibTargetSpec("chessboard:6x8:20"), {});
  EXPECT_FALSE(sheet.landscape);
  EXPECT_DOUBLE_EQ(sheet.paper.width_mm, 210);
  SheetOptions letter;
  letter.paper = "letter";
  const TargetSheet on_letter =
      LayoutCalibTargetSheet(ParseCalibTargetSpec("chessboard:6x8:20"), letter);
  EXPECT_DOUBLE_EQ(on_letter.paper.width_mm, 215.9);
  EXPECT_DOUBLE_EQ(on_letter.paper.height_mm, 279.4);
}

TEST(TargetSheet, TextNamesTheSpecTheAdviceAndTheCommand) {
  SheetOptions options;
  options.command = "kincal print --target aprilgrid:4x3:30:0.3 --out s.pdf";
  const TargetSheet sheet = LayoutCalibTargetSheet(
      ParseCalibTargetSpec("aprilgrid:4x3:30:0.3"), options);
  std::string all;  // wrapped at spaces: joined back with spaces
  for (const SheetText& t : sheet.texts) all += t.text + " ";
  EXPECT_THAT(all, HasSubstr("target: aprilgrid:4x3:30:0.3"));
  EXPECT_THAT(all, HasSubstr("black square 30 mm, gap 9 mm"));
  EXPECT_THAT(all, HasSubstr("actual size, no fit-to-page"));
  EXPECT_THAT(all, HasSubstr("made by: " + options.command));
  EXPECT_THAT(all, HasSubstr("100 mm"));
}

TEST(TargetSheet, BoardTooLargeNamesTheLargestSizeAndALargerPaper) {
  try {
    LayoutCalibTargetSheet(ParseCalibTargetSpec("chessboard:9x6:30"), {});
    FAIL() << "a 300 x 210 mm board fits on A4";
  } catch (const InputError& e) {
    // A4 landscape: 161.6 mm of height for 7 squares -> 23.08 mm.
    EXPECT_THAT(e.what(), HasSubstr("largest square size that fits is 23 mm"));
    EXPECT_THAT(e.what(), HasSubstr("--paper A3"));
  }
  SheetOptions a3;
  a3.paper = "A3";
  EXPECT_NO_THROW(
      LayoutCalibTargetSheet(ParseCalibTargetSpec("chessboard:9x6:30"), a3));
  EXPECT_THROW(PaperByName("A5"), InputError);
}

// The AprilGrid as printed, seen head-on, gives every tag with the id and
// corner positions camcal's detector pairs with CalibTargetSpec::Points().
// Kalibr's layout and the other layouts camcal reads (first id, column
// order, top-left origin, turned tags): every printed corner is detected
// where the spec puts it.
TEST(TargetSheet, AprilGridDetectedWhereTheSpecPutsItsCorners) {
  for (const char* text :
       {"aprilgrid:5x4:24:0.3",
        "aprilgrid:5x4:24:0.3:first=7:order=columns:origin=top-left",
        "aprilgrid:5x4:24:0.5:rotation=90", "aprilgrid:5x4:24:0.3:rotation=180",
        "aprilgrid:5x4:24:0.3:origin=top-left:rotation=270"}) {
    const CalibTargetSpec spec = ParseCalibTargetSpec(text);
    const TargetSheet sheet = LayoutCalibTargetSheet(spec, {});
    const double px_per_mm = 4;
    CalibTargetDetector detector(spec);
    const TargetObservation obs = detector.Detect(Rasterise(sheet, px_per_mm));
    ASSERT_EQ(obs.pixels.size(), 4u * 20u) << text;  // every tag, once
    double worst = 0;
    for (size_t i = 0; i < obs.pixels.size(); ++i) {
      worst = std::max(
          worst,
          (obs.pixels[i] - ExpectedPixel(sheet, obs.p_in_target[i], px_per_mm))
              .norm());
    }
    EXPECT_LT(worst, 0.5) << text << ": px at " << px_per_mm << " px/mm";
  }
}

TEST(TargetSheet, ChessboardDetectedAtTheSpecSquareSize) {
  const CalibTargetSpec spec = ParseCalibTargetSpec("chessboard:7x5:20");
  const TargetSheet sheet = LayoutCalibTargetSheet(spec, {});
  const double px_per_mm = 4;
  CalibTargetDetector detector(spec);
  const TargetObservation obs = detector.Detect(Rasterise(sheet, px_per_mm));
  ASSERT_EQ(obs.pixels.size(), 35u);
  // OpenCV may list the corners from either end of the board.
  double forward = 0, reversed = 0;
  for (size_t i = 0; i < obs.pixels.size(); ++i) {
    const size_t j = obs.pixels.size() - 1 - i;
    forward = std::max(
        forward,
        (obs.pixels[i] - ExpectedPixel(sheet, obs.p_in_target[i], px_per_mm))
            .norm());
    reversed = std::max(
        reversed,
        (obs.pixels[i] - ExpectedPixel(sheet, obs.p_in_target[j], px_per_mm))
            .norm());
  }
  EXPECT_LT(std::min(forward, reversed), 0.5);
}

TEST(TargetSheet, ToolTagsAtTheirSizesLabelledAndApart) {
  Target target;
  target.family = "tag36h11";
  target.tags.resize(2);
  target.tags[0].id = 7;
  target.tags[0].size_mm = 20;
  target.tags[1].id = 2;
  target.tags[1].size_mm = 30;
  const TargetSheet sheet = LayoutToolTargetSheet(target, "tool.yaml", {});
  std::string all;
  for (const SheetText& t : sheet.texts) all += t.text + "\n";
  EXPECT_THAT(all, HasSubstr("id 2, 30 mm"));
  EXPECT_THAT(all, HasSubstr("id 7, 20 mm"));
  EXPECT_THAT(all, HasSubstr("target: tool.yaml"));
  // tag36h11: the black square is 8 of the 10 cells; id 2 comes first.
  const Box first = BoundingBox({sheet.black.front()});
  EXPECT_NEAR(first.y1 - first.y0, 30.0 / 8, 1e-9);
  std::vector<SheetRect> id2, id7;
  for (const SheetRect& r : sheet.black) {
    (r.x < first.x0 + 40 ? id2 : id7).push_back(r);
  }
  const Box a = BoundingBox(id2), b = BoundingBox(id7);
  EXPECT_NEAR(a.x1 - a.x0, 30, 1e-9);
  EXPECT_NEAR(a.y1 - a.y0, 30, 1e-9);
  EXPECT_NEAR(b.x1 - b.x0, 20, 1e-9);
  EXPECT_NEAR(b.y1 - b.y0, 20, 1e-9);
  EXPECT_GE(b.x0 - a.x1, 10);

  target.tags[1].size_mm = 400;
  EXPECT_THROW(LayoutToolTargetSheet(target, "tool.yaml", {}), InputError);
}

TEST(TargetSheet, SvgInMillimetresWithTheCommand) {
  SheetOptions options;
  options.command = "kincal print --target chessboard:4x3:20 --out a.svg";
  const TargetSheet sheet = LayoutCalibTargetSheet(
      ParseCalibTargetSpec("chessboard:4x3:20"), options);
  const std::string svg = SheetToSvg(sheet);
  EXPECT_THAT(svg, HasSubstr("width=\"210mm\" height=\"297mm\" "
                             "viewBox=\"0 0 210 297\""));
  EXPECT_THAT(svg, HasSubstr("<desc>made by: " + options.command + "</desc>"));
  const size_t comment = svg.find("<!--");
  ASSERT_NE(comment, std::string::npos);
  const std::string body =
      svg.substr(comment + 4, svg.find("-->") - comment - 4);
  EXPECT_THAT(body, HasSubstr("chessboard:4x3:20"));
  EXPECT_THAT(body, Not(HasSubstr("--")));  // not allowed in an XML comment
  EXPECT_THAT(svg, HasSubstr("M"));
}

TEST(TargetSheet, PdfAtPaperSizeWithTheCommandInItsMetadata) {
  SheetOptions options;
  options.command = "kincal print --target chessboard:4x3:20 --out a.pdf";
  const TargetSheet sheet = LayoutCalibTargetSheet(
      ParseCalibTargetSpec("chessboard:4x3:20"), options);
  const std::string pdf = SheetToPdf(sheet);
  EXPECT_EQ(pdf.substr(0, 5), "%PDF-");
  // 210 x 297 mm in points (72 per inch).
  EXPECT_NE(pdf.find("/MediaBox [ 0 0 595.275591 841.889764 ]"),
            std::string::npos);
  EXPECT_NE(pdf.find("/Subject (made by: " + options.command + ")"),
            std::string::npos);
}

TEST(TargetSheet, WritesOnlyPdfOrSvg) {
  const TargetSheet sheet =
      LayoutCalibTargetSheet(ParseCalibTargetSpec("chessboard:4x3:20"), {});
  const std::string dir = testing::MakeTempDir("target_sheet");
  EXPECT_THROW(WriteTargetSheet(sheet, dir + "/sheet.png"), InputError);
  EXPECT_FALSE(testing::Exists(dir + "/sheet.png"));
  WriteTargetSheet(sheet, dir + "/sheet.SVG");
  EXPECT_TRUE(testing::Exists(dir + "/sheet.SVG"));
}

}  // namespace
}  // namespace kincal
