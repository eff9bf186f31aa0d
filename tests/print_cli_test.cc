// kincal print end to end: JSON fields, the sheet's physical size (the PDF
// rasterised at 600 dpi by pdftoppm and measured), the SVG in mm, the
// command recorded, and a board too large for the paper: exit 2, no file.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "data/atomic_file.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::Exists;
using ::testing::HasSubstr;
using testing::RunKincal;
using testing::RunShell;

constexpr double kDpi = 600;
constexpr double kPxPerMm = kDpi / 25.4;

bool HavePdftoppm() {
  return RunShell("command -v pdftoppm >/dev/null 2>&1").exit_code == 0;
}

// The page at 600 dpi, 8-bit gray; empty when pdftoppm fails.
cv::Mat Rasterise(const std::string& pdf) {
  const std::string prefix = pdf + ".600dpi";
  const auto r = RunShell("pdftoppm -r 600 -gray -singlefile '" + pdf + "' '" +
                          prefix + "'");
  if (r.exit_code != 0) return cv::Mat();
  return cv::imread(prefix + ".pgm", cv::IMREAD_GRAYSCALE);
}

// Black runs (value < 128) of one image row: [begin, end) in pixels, each
// edge placed where the grey level crosses 128 between two pixel centres
// (pdftoppm antialiases: an edge pixel's grey is its white fraction), so a
// run is measured to a fraction of a pixel.
std::vector<std::pair<double, double>> BlackRuns(const cv::Mat& page, int row) {
  std::vector<std::pair<double, double>> runs;
  const uint8_t* p = page.ptr<uint8_t>(row);
  auto crossing = [p](int a, int b) {  // pixels a, b = a + 1; p[a] != p[b]
    return a + 0.5 + (p[a] - 128.0) / (p[a] - p[b]);
  };
  for (int x = 0; x < page.cols;) {
    if (p[x] >= 128) {
      ++x;
      continue;
    }
    const int begin = x;
    while (x < page.cols && p[x] < 128) ++x;
    runs.push_back({begin > 0 ? crossing(begin - 1, begin) : 0.0,
                    x < page.cols ? crossing(x - 1, x) : double(page.cols)});
  }
  return runs;
}

struct Measured {
  double bar_mm = 0;  // first to last tick of the scale bar, centre to centre
  double pattern_width_mm = 0, pattern_height_mm = 0;  // black bounding box
  // Black runs 1 mm below the pattern's top: the top row of chessboard
  // squares, or the top sides of the top row of tags (their black ring).
  std::vector<double> top_runs_mm;
};

// Finds the scale bar's baseline (the first row from the top with a black
// run over 90 mm: pattern cells are shorter), measures its ticks 4 mm above
// it, and the bounding box of every black pixel above the bar's ticks.
Measured MeasureSheet(const cv::Mat& page) {
  Measured m;
  int baseline = -1;
  for (int y = 0; y < page.rows && baseline < 0; ++y) {
    for (const auto& run : BlackRuns(page, y)) {
      if (run.second - run.first > 90 * kPxPerMm) baseline = y;
    }
  }
  if (baseline < 0) return m;
  const auto ticks =
      BlackRuns(page, baseline - static_cast<int>(std::lround(4 * kPxPerMm)));
  if (ticks.size() == 3) {  // the long ticks at 0, 50 and 100 mm
    m.bar_mm = ((ticks[2].first + ticks[2].second) -
                (ticks[0].first + ticks[0].second)) /
               2.0 / kPxPerMm;
  }
  const int pattern_rows =
      baseline - static_cast<int>(std::lround(6 * kPxPerMm));
  double x0 = page.cols, x1 = -1;
  int y0 = page.rows, y1 = -1;
  for (int y = 0; y < pattern_rows; ++y) {
    for (const auto& run : BlackRuns(page, y)) {
      x0 = std::min(x0, run.first);
      x1 = std::max(x1, run.second);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y + 1);
    }
  }
  m.pattern_width_mm = (x1 - x0) / kPxPerMm;
  m.pattern_height_mm = (y1 - y0) / kPxPerMm;
  if (y1 < 0) return m;
  for (const auto& run :
       BlackRuns(page, y0 + static_cast<int>(std::lround(kPxPerMm)))) {
    m.top_runs_mm.push_back((run.second - run.first) / kPxPerMm);
  }
  return m;
}

void ExpectWithinTenthOfAPercent(double measured, double stated,
                                 const std::string& what) {
  const double percent = 100 * (measured - stated) / stated;
  std::printf("  %s: stated %.3f mm, measured %.3f mm at 600 dpi (%+.3f %%)\n",
              what.c_str(), stated, measured, percent);
  EXPECT_LT(std::abs(percent), 0.1) << what;
}

TEST(PrintCli, ChessboardPdfAtPhysicalSize) {
  const std::string dir = testing::MakeTempDir("print");
  const std::string spec = "chessboard:9x6:20";
  const auto r =
      RunKincal("print --target " + spec + " --out " + dir + "/cb.pdf --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["out"], dir + "/cb.pdf");
  EXPECT_EQ(j["target"], spec);
  // 10 x 7 squares of 20 mm fit A4 only in landscape.
  EXPECT_DOUBLE_EQ(j["width_mm"].get<double>(), 297);
  EXPECT_DOUBLE_EQ(j["height_mm"].get<double>(), 210);
  const std::string pdf = ReadFile(dir + "/cb.pdf");
  EXPECT_EQ(pdf.substr(0, 5), "%PDF-");
  EXPECT_THAT(pdf,
              HasSubstr("/Subject (made by: kincal print --target " + spec));
  if (!HavePdftoppm()) {
    GTEST_SKIP() << "pdftoppm (Debian poppler-utils) is not installed: the "
                    "600 dpi size check is skipped";
  }
  const cv::Mat page = Rasterise(dir + "/cb.pdf");
  ASSERT_FALSE(page.empty());
  EXPECT_NEAR(page.cols / kPxPerMm, 297, 0.1);
  const Measured m = MeasureSheet(page);
  ExpectWithinTenthOfAPercent(m.bar_mm, 100, "scale bar");
  ExpectWithinTenthOfAPercent(m.pattern_width_mm / 10, 20,
                              "chessboard square (width / 10)");
  ExpectWithinTenthOfAPercent(m.pattern_height_mm / 7, 20,
                              "chessboard square (height / 7)");
  ASSERT_EQ(m.top_runs_mm.size(), 5u);  // black squares of the top row
  for (double run : m.top_runs_mm) {
    ExpectWithinTenthOfAPercent(run, 20, "one chessboard square");
  }
}

TEST(PrintCli, AprilGridPdfAtPhysicalSize) {
  const std::string dir = testing::MakeTempDir("print");
  const std::string spec = "aprilgrid:6x6:24:0.3";
  const auto r = RunKincal("print --target " + spec + " --out " + dir +
                           "/ag.pdf --paper A4 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["target"], spec);
  EXPECT_DOUBLE_EQ(j["width_mm"].get<double>(), 210);
  EXPECT_DOUBLE_EQ(j["height_mm"].get<double>(), 297);
  if (!HavePdftoppm()) {
    GTEST_SKIP() << "pdftoppm (Debian poppler-utils) is not installed: the "
                    "600 dpi size check is skipped";
  }
  const cv::Mat page = Rasterise(dir + "/ag.pdf");
  ASSERT_FALSE(page.empty());
  const Measured m = MeasureSheet(page);
  ExpectWithinTenthOfAPercent(m.bar_mm, 100, "scale bar");
  // 6 tags of 24 mm and 5 gaps of 7.2 mm = 180 mm each way; the tags' outer
  // black ring is the black square.
  const double stated = 6 * 24 + 5 * 0.3 * 24;
  ExpectWithinTenthOfAPercent(m.pattern_width_mm, stated,
                              "AprilGrid width (6 tags, 5 gaps)");
  ExpectWithinTenthOfAPercent(m.pattern_height_mm, stated,
                              "AprilGrid height (6 tags, 5 gaps)");
  ASSERT_EQ(m.top_runs_mm.size(), 6u);  // top sides of the top row of tags
  for (double run : m.top_runs_mm) {
    ExpectWithinTenthOfAPercent(run, 24, "one tag's black square");
  }
}

TEST(PrintCli, SvgInMillimetresAndToolTargetYaml) {
  const std::string dir = testing::MakeTempDir("print");
  auto r = RunKincal("print --target aprilgrid:4x3:30:0.3 --out " + dir +
                     "/ag.svg --paper letter --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["width_mm"].get<double>(), 215.9);
  EXPECT_DOUBLE_EQ(j["height_mm"].get<double>(), 279.4);
  const std::string svg = ReadFile(dir + "/ag.svg");
  EXPECT_THAT(svg, HasSubstr("width=\"215.9mm\" height=\"279.4mm\""));
  EXPECT_THAT(svg, HasSubstr("<desc>made by: kincal print --target "
                             "aprilgrid:4x3:30:0.3"));

  WriteFileAtomic(dir + "/tool.yaml",
                  "kincal_target: 1\nfamily: tag36h11\ntags:\n"
                  "  - {id: 4, size: 25, tool_from_tag: {R: [1,0,0, 0,1,0, "
                  "0,0,1], t: [0, 0, 0]}}\n"
                  "  - {id: 9, size: 40, tool_from_tag: {R: [1,0,0, 0,1,0, "
                  "0,0,1], t: [60, 0, 0]}}\n"
                  "tip_in_tool: [0, 0, 150]\n");
  r = RunKincal("print --target " + dir + "/tool.yaml --out " + dir +
                "/tool.svg --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["target"], dir + "/tool.yaml");
  const std::string tool = ReadFile(dir + "/tool.svg");
  EXPECT_THAT(tool, HasSubstr(">id 4, 25 mm<"));
  EXPECT_THAT(tool, HasSubstr(">id 9, 40 mm<"));
}

// print is an image command (cairo, OpenCV): bin/kincal lists it and hands
// it to kincal-vision, whose --help is the one shown.
TEST(PrintCli, SameHelpFromBothBinaries) {
  const std::string kincal = testing::KincalBinary();
  const std::string vision =
      kincal.substr(0, kincal.find_last_of('/') + 1) + "kincal-vision";
  const auto a = RunKincal("print --help");
  const auto b = RunShell(vision + " print --help");
  ASSERT_EQ(a.exit_code, 0);
  EXPECT_THAT(a.out, HasSubstr("--paper"));
  std::string expected = b.out;
  for (size_t at = expected.find(vision); at != std::string::npos;
       at = expected.find(vision, at + kincal.size())) {
    expected.replace(at, vision.size(), kincal);
  }
  EXPECT_EQ(a.out, expected);
}

TEST(PrintCli, BadInputExits2AndWritesNothing) {
  const std::string dir = testing::MakeTempDir("print");
  auto r = RunKincal("print --target chessboard:9x6:30 --out " + dir +
                     "/big.pdf --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("largest square size that fits is 23 mm"));
  EXPECT_THAT(r.err, HasSubstr("--paper A3"));
  EXPECT_EQ(r.out, "");
  EXPECT_FALSE(Exists(dir + "/big.pdf"));

  r = RunKincal("print --target chessboard:9x6:20 --out " + dir + "/cb.png");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr(".pdf or .svg"));
  EXPECT_FALSE(Exists(dir + "/cb.png"));

  r = RunKincal("print --target chessboard:9x6:20 --paper A5 --out " + dir +
                "/cb.pdf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("A4, A3 or letter"));
  EXPECT_FALSE(Exists(dir + "/cb.pdf"));

  r = RunKincal("print --target " + dir + "/missing.yaml --out " + dir +
                "/t.pdf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("no such file; expected chessboard:"));
  EXPECT_FALSE(Exists(dir + "/t.pdf"));
}

}  // namespace
}  // namespace kincal
