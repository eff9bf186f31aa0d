// End-to-end: `kincal camcal` on OpenCV's stereo images, and its bad-input
// exits (code 2, nothing written).

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "camcal/cameramodel.h"
#include "camcal/rig.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

std::string StereoDir() {
  return testing::SharedDataDir() + "/opencv-stereo-left-right";
}

// The default (least squares, board warp, 4-sigma outlier rejection: as
// mrcal-calibrate-cameras) on the stereo pairs. mrcal's default on the same
// corners (bench/mrcal_crossval.py, mrcal 2.2, OPENCV5, outlier rejection,
// regularisation, calobject_warp): 36 corners rejected, warp (0.0015,
// -0.00632) squares, halves 0.049 / 0.153 px within 160 px of the centre
// and 2.778 / 0.411 px over the image (left / right; projection difference,
// rays at infinity, rotation fitted within 160 px); fx 534.186 / 537.894
// (sigma 0.313 / 0.322), cx 341.851 / 326.771 (sigma 0.402 / 0.443).
// kincal's default applies mrcal's lens regulariser with mrcal's scales, so
// it is mrcal's default: measured 0.00 mrcal sigma from it, halves 0.048 /
// 0.150 px within 160 px and 2.780 / 0.419 px over the image (kincal's
// projection difference; mrcal's code gives 2.781 / 0.411 for the same
// halves). The halves must agree within 160 px as well as the bar
// (0.05 / 0.16 px) and over the whole image within 5 % of mrcal's; the
// intrinsics within 0.1 of mrcal's sigma.
void ExpectDefaultAsConsistentAsMrcal(const nlohmann::json& j) {
  const auto& rejection = j.at("outlier_rejection");
  EXPECT_EQ(rejection.at("reject_sigma").get<double>(), 4.0);
  EXPECT_GT(rejection.at("corners").get<int>(), 14);  // 1 %..7 % of 1404
  EXPECT_LT(rejection.at("corners").get<int>(), 100);
  ASSERT_EQ(j.at("board_warp").size(), 2u);
  EXPECT_NEAR(j["board_warp"][0].get<double>(), 0.0015, 0.001);
  EXPECT_NEAR(j["board_warp"][1].get<double>(), -0.0063, 0.001);
  const double focus_bar[2] = {0.05, 0.16}, mrcal_whole[2] = {2.778, 0.411};
  const double mrcal_fx[2] = {534.186, 537.894}, sigma_fx[2] = {0.313, 0.322};
  const double mrcal_cx[2] = {341.851, 326.771}, sigma_cx[2] = {0.402, 0.443};
  for (size_t c = 0; c < 2; ++c) {
    const auto& cam = j.at("cameras")[c];
    EXPECT_EQ(cam.at("half_diff_focus_radius_px").get<double>(), 160.0);
    EXPECT_LE(cam.at("half_diff_focus_rms_px").get<double>(), focus_bar[c]);
    EXPECT_LE(cam.at("half_diff_rms_px").get<double>(), 1.05 * mrcal_whole[c]);
    EXPECT_LT(std::abs(cam.at("fx").get<double>() - mrcal_fx[c]),
              0.1 * sigma_fx[c]);
    EXPECT_LT(std::abs(cam.at("cx").get<double>() - mrcal_cx[c]),
              0.1 * sigma_cx[c]);
    // Held out on the other half's inliers: close to the inlier RMS.
    EXPECT_LT(cam.at("holdout_rms_px").get<double>(), 0.25);
    EXPECT_LT(cam.at("rms_px").get<double>(), 0.2);
  }
}

TEST(CamcalCli, StereoChessboardJsonAndRig) {
  KINCAL_REQUIRE_SHARED_DATA("opencv-stereo-left-right");
  const std::string out = testing::MakeTempDir("camcal") + "/rig.yaml";
  const std::string prefix = out.substr(0, out.size() - 9) + "/mrcal";
  const RunResult r =
      RunKincal("camcal --left '" + StereoDir() + "/left*.jpg' --right '" +
                StereoDir() + "/right*.jpg' --target chessboard:9x6:1 --out " +
                out + " --out-cameramodel " + prefix + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_LE(j.at("rms_px").get<double>(), 0.445);
  EXPECT_NEAR(j.at("baseline").get<double>(), 3.34, 0.05);
  ASSERT_EQ(j.at("cameras").size(), 2u);
  for (const auto& c : j.at("cameras")) {
    for (const char* key : {"fx", "fy", "cx", "cy", "rms_px"}) {
      EXPECT_TRUE(c.at(key).is_number()) << key;
    }
    EXPECT_EQ(c.at("distortion").size(), 5u);
    EXPECT_EQ(c.at("view_rms_px").size(), 13u);
    EXPECT_TRUE(c.at("holdout_rms_px").is_number());
    EXPECT_TRUE(c.at("sigma").at("fx").is_number());
    EXPECT_NEAR(c.at("fx").get<double>(), 537, 10);
    // Residuals over the image: 8 x 6 cells holding every corner once, and
    // the cells' RMS values combine to the camera's RMS.
    const auto& g = c.at("image_grid");
    ASSERT_EQ(g.at("cols"), 8);
    ASSERT_EQ(g.at("rows"), 6);
    ASSERT_EQ(g.at("count").size(), 48u);
    EXPECT_NEAR(g.at("cell_w_px").get<double>() * 8, 640, 1e-9);
    int corners = 0, cells_seen = 0;
    double ss = 0;
    for (size_t k = 0; k < 48; ++k) {
      const int n = g["count"][k].get<int>();
      corners += n;
      if (n == 0) {
        EXPECT_TRUE(g["rms_px"][k].is_null());
        continue;
      }
      ++cells_seen;
      ss += n * std::pow(g["rms_px"][k].get<double>(), 2);
      EXPECT_LE(std::hypot(g["mean_dx_px"][k].get<double>(),
                           g["mean_dy_px"][k].get<double>()),
                g["rms_px"][k].get<double>() + 1e-12);
    }
    // The cells hold the inliers; with the rejected corners, every corner.
    EXPECT_EQ(corners, c.at("points").get<int>());
    EXPECT_EQ(c.at("rejected_views").get<int>(), 0);
    EXPECT_EQ(corners + c.at("rejected_corners").get<int>(), 13 * 54);
    EXPECT_GT(cells_seen, 20);
    EXPECT_NEAR(std::sqrt(ss / corners), c.at("rms_px").get<double>(), 1e-9);
  }
  EXPECT_NE(j.at("command").get<std::string>().find("camcal"),
            std::string::npos);
  ExpectDefaultAsConsistentAsMrcal(j);
  // The rig file reads back and agrees with the JSON.
  const Rig rig = ReadRigYaml(out);
  ASSERT_EQ(rig.cameras.size(), 2u);
  EXPECT_DOUBLE_EQ(rig.cameras[1].intrinsics.fx,
                   j["cameras"][1]["fx"].get<double>());
  EXPECT_NEAR(rig.BaselineMm(), j["baseline"].get<double>(), 1e-9);

  // Projection uncertainty: smallest at the centre, a valid region around it
  // (also in rig.yaml), and the mrcal models that import back to the rig.
  for (size_t c = 0; c < 2; ++c) {
    const auto& u = j["cameras"][c].at("projection_uncertainty");
    EXPECT_TRUE(u.at("distance").is_null());  // infinity
    const double centre = u["centre"]["sigma_px"].get<double>();
    EXPECT_GT(centre, 0.01);
    EXPECT_LT(centre, 1.0);
    for (const auto& corner : u.at("corners")) {
      EXPECT_GT(corner["sigma_px"].get<double>(), 2 * centre);
    }
    EXPECT_EQ(u["grid"]["sigma_px"].size(), 48u);
    EXPECT_GE(u.at("valid_intrinsics_region").size(), 4u);
    EXPECT_EQ(rig.cameras[c].valid_intrinsics_region.size(),
              u["valid_intrinsics_region"].size());
  }
  const std::string imported = testing::MakeTempDir("camcal") + "/back.yaml";
  ASSERT_EQ(RunKincal("import cameramodel --camera left=" + prefix +
                      "-left.cameramodel --camera right=" + prefix +
                      "-right.cameramodel --unit-mm 1 --out " + imported)
                .exit_code,
            0);
  const Rig back = ReadRigYaml(imported);
  ASSERT_EQ(back.cameras.size(), 2u);
  for (size_t c = 0; c < 2; ++c) {
    const CameraIntrinsics& a = rig.cameras[c].intrinsics;
    const CameraIntrinsics& b = back.cameras[c].intrinsics;
    EXPECT_EQ(a.fx, b.fx);
    EXPECT_EQ(a.cy, b.cy);
    EXPECT_EQ(a.distortion, b.distortion);
    const Eigen::Vector3d p(0.3, -0.2, 25);
    EXPECT_LT((Project(a, rig.cameras[c].cam_from_rig * p) -
               Project(b, back.cameras[c].cam_from_rig * p))
                  .norm(),
              1e-9);
  }
  EXPECT_NEAR(back.BaselineMm(), rig.BaselineMm(), 1e-12);
}

// The 8-coefficient model converges with the default regularisers (k4..k6
// and mrcal's lens regulariser) and reports their share of the cost;
// without both the solve stops at 200 iterations and writes nothing (exit
// 1); a negative weight is bad input.
TEST(CamcalCli, RationalModelConvergesWithRegularizer) {
  KINCAL_REQUIRE_SHARED_DATA("opencv-stereo-left-right");
  const std::string dir = testing::MakeTempDir("camcal_opencv8");
  const std::string out = dir + "/rig.yaml";
  const std::string images =
      "camcal --left '" + StereoDir() + "/left*.jpg' --right '" + StereoDir() +
      "/right*.jpg' --target chessboard:9x6:1 --out " + out + " --distortion 8";
  const RunResult r = RunKincal(images + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("converged").get<bool>());
  EXPECT_LT(j.at("iterations").get<int>(), 200);
  EXPECT_LE(j.at("rms_px").get<double>(), 0.445);
  const auto& reg = j.at("regularization");
  EXPECT_DOUBLE_EQ(reg.at("weight").get<double>(), 0.005);
  EXPECT_DOUBLE_EQ(reg.at("lens_weight").get<double>(), 1.0);
  EXPECT_GT(reg.at("share").get<double>(), 0.0);
  EXPECT_LT(reg.at("share").get<double>(), 0.001);
  for (const auto& c : j.at("cameras")) {
    EXPECT_EQ(c.at("distortion").size(), 8u);
    EXPECT_LT(c.at("half_diff_rms_px").get<double>(), 10.0);
  }
  std::remove(out.c_str());
  EXPECT_EQ(RunKincal(images + " --regularize 0 --regularize-lens 0").exit_code,
            1);
  EXPECT_FALSE(std::ifstream(out).good());
  EXPECT_EQ(RunKincal(images + " --regularize -1").exit_code, 2);
  EXPECT_EQ(RunKincal(images + " --regularize-lens -1").exit_code, 2);
}

TEST(CamcalCli, BadInputExitsTwoAndWritesNothing) {
  const std::string dir = testing::MakeTempDir("camcal_bad");
  const std::string out = dir + "/rig.yaml";
  const std::string left = "'" + StereoDir() + "/left*.jpg'";
  // Bad target spec (checked before any image is read).
  EXPECT_EQ(RunKincal("camcal --left " + left +
                      " --target chessboard:9x6 --out " + out)
                .exit_code,
            2);
  EXPECT_EQ(RunKincal("camcal --left " + left +
                      " --target squares:9x6:1 --out " + out)
                .exit_code,
            2);
  // A glob with no images.
  EXPECT_EQ(RunKincal("camcal --left '" + dir +
                      "/none*.png' --target chessboard:9x6:1 --out " + out)
                .exit_code,
            2);
  // Unreadable images.
  {
    FILE* f = std::fopen((dir + "/img0.png").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("not a png", f);
    std::fclose(f);
  }
  EXPECT_EQ(RunKincal("camcal --left '" + dir +
                      "/img*.png' --target chessboard:9x6:1 --out " + out)
                .exit_code,
            2);
  // Missing required option.
  EXPECT_EQ(RunKincal("camcal --left " + left + " --out " + out).exit_code, 2);
  if (testing::Exists(StereoDir())) {
    // Target not found (wrong size): too few views.
    EXPECT_EQ(RunKincal("camcal --left " + left +
                        " --target chessboard:7x7:1 --out " + out)
                  .exit_code,
              2);
    // Unequal left/right counts.
    EXPECT_EQ(RunKincal("camcal --left " + left + " --right '" + StereoDir() +
                        "/right0*.jpg' --target chessboard:9x6:1 --out " + out)
                  .exit_code,
              2);
  }
  EXPECT_FALSE(testing::Exists(out));
}

}  // namespace
}  // namespace kincal
