#include "camcal/plausibility.h"

#include <gtest/gtest.h>

#include <cmath>

namespace kincal {
namespace {

// A stereo summary: cameras `baseline` apart along x, boards at `depth`
// along z in views that are used, and one unused view at depth 1.
CalibrationSummary Summary(double baseline, double depth) {
  CalibrationSummary s;
  s.rig.cameras.resize(2);
  s.rig.cameras[1].cam_from_rig.t = Eigen::Vector3d(-baseline, 0, 0);
  s.baseline = baseline;
  for (double d : {0.9 * depth, depth, 1.1 * depth}) {
    Rigid3 pose;
    pose.t = Eigen::Vector3d(0.1 * d, 0, d);
    s.rig_from_target.push_back(pose);
    s.view_used.push_back(true);
  }
  Rigid3 unused;
  unused.t = Eigen::Vector3d(0, 0, 1);
  s.rig_from_target.push_back(unused);
  s.view_used.push_back(false);
  return s;
}

TEST(BoardPlausibility, SizeInMetresIsNamedWithTheMillimetreSpec) {
  const std::string why = BoardSizeImplausible(0.03, "aprilgrid:6x6:0.03:0.3");
  EXPECT_NE(why.find("looks like metres"), std::string::npos) << why;
  EXPECT_NE(why.find("--target aprilgrid:6x6:30:0.3"), std::string::npos)
      << why;
  EXPECT_NE(BoardSizeImplausible(0.025, "chessboard:9x6:0.025")
                .find("chessboard:9x6:25 "),
            std::string::npos);
  EXPECT_EQ(BoardSizeImplausible(30, "aprilgrid:6x6:30:0.3"), "");
  EXPECT_EQ(BoardSizeImplausible(1, "chessboard:9x6:1"), "");  // squares
  EXPECT_EQ(BoardSizeImplausible(1.5, "chessboard:9x6:1.5"), "");
}

TEST(BoardPlausibility, MedianDistanceSkipsUnusedViews) {
  EXPECT_NEAR(MedianBoardDistance(Summary(120, 800)), 800 * std::hypot(1, 0.1),
              1e-9);
  EXPECT_TRUE(std::isnan(MedianBoardDistance(CalibrationSummary())));
}

TEST(BoardPlausibility, SolvedRigTooSmallIsNamed) {
  // A rig solved with a board of 2 "mm" that were 2 cm: the board 50 mm
  // away is fine, 15 mm is not.
  EXPECT_EQ(SolvedRigImplausible(Summary(120, 800), 30, "chessboard:9x6:30"),
            "");
  EXPECT_EQ(SolvedRigImplausible(Summary(12, 50), 2, "chessboard:9x6:2"), "");
  const std::string near =
      SolvedRigImplausible(Summary(12, 15), 2, "chessboard:9x6:2");
  EXPECT_NE(near.find("seen 15"), std::string::npos) << near;
  EXPECT_NE(near.find("chessboard:9x6:2000"), std::string::npos) << near;
  const std::string narrow =
      SolvedRigImplausible(Summary(0.12, 800), 30, "chessboard:9x6:30");
  EXPECT_NE(narrow.find("0.12 mm apart"), std::string::npos) << narrow;
  // Squares: board units, no check.
  EXPECT_EQ(SolvedRigImplausible(Summary(0.12, 15), 1, "chessboard:9x6:1"), "");
  // One camera: no baseline.
  CalibrationSummary mono = Summary(0, 800);
  mono.rig.cameras.resize(1);
  EXPECT_EQ(SolvedRigImplausible(mono, 30, "chessboard:9x6:30"), "");
}

}  // namespace
}  // namespace kincal
