// The camera and tracking sections: intrinsics and camcal's per-view and
// over-the-image figures; points.csv read strictly.

#include "report/camera_sections.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "data/error.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

Rig TwoCameras() {
  Rig rig;
  rig.cameras.resize(2);
  rig.cameras[0].intrinsics.name = "left";
  rig.cameras[0].intrinsics.width = 640;
  rig.cameras[0].intrinsics.height = 480;
  rig.cameras[0].intrinsics.fx = 800;
  rig.cameras[1].intrinsics = rig.cameras[0].intrinsics;
  rig.cameras[1].intrinsics.name = "right";
  return rig;
}

TEST(CameraSectionsTest, CamcalJsonGivesPerViewAndImageFigures) {
  nlohmann::json camcal = {{"cameras",
                            {{{"name", "left"},
                              {"rms_px", 0.21},
                              {"view_rms_px", {0.2, 0.3, 0.9}},
                              {"image_grid",
                               {{"cols", 2},
                                {"rows", 1},
                                {"cell_w_px", 320},
                                {"cell_h_px", 480},
                                {"rms_px", {0.2, 0.437}},
                                {"mean_dx_px", {0.1, -0.1}},
                                {"mean_dy_px", {0.0, 0.05}}}}}}}};
  HtmlReport page("t");
  AddCameraSection(TwoCameras(), camcal, "c.json", &page);
  const std::string html = page.Page("");
  EXPECT_EQ(page.sections(), std::vector<std::string>{"camera"});
  EXPECT_EQ(page.figures(), 2);  // per view, over the image
  EXPECT_THAT(html, HasSubstr("<td>left</td><td>640 x 480</td>"));
  EXPECT_THAT(html, HasSubstr("Reprojection error per view"));
  EXPECT_THAT(html, HasSubstr("residual over the image"));
  // The colour bar is labelled at round values, not the data's 0.437.
  EXPECT_THAT(html, HasSubstr(">0.4<"));
  EXPECT_THAT(html, Not(HasSubstr(">0.437<")));
}

// camcal's projection_uncertainty grid becomes a heat map whose colour scale
// is capped at 4x the centre's sigma (the extrapolated corner shows at the
// cap), named in the caption.
TEST(CameraSectionsTest, ProjectionUncertaintyGridGivesAHeatMap) {
  nlohmann::json camcal = {
      {"cameras",
       {{{"name", "left"},
         {"width", 640},
         {"height", 480},
         {"projection_uncertainty",
          {{"distance", nullptr},
           {"centre", {{"pixel", {319.5, 239.5}}, {"sigma_px", 0.25}}},
           {"valid_threshold_px", 0.5},
           {"grid",
            {{"cols", 2},
             {"rows", 2},
             {"sigma_px", {0.2, 0.3, 0.4, 10.8}}}}}}}}}};
  HtmlReport page("t");
  AddCameraSection(TwoCameras(), camcal, "c.json", &page);
  const std::string html = page.Page("");
  EXPECT_EQ(page.figures(), 1);
  EXPECT_THAT(html, HasSubstr("left: projection uncertainty"));
  EXPECT_THAT(html, HasSubstr("a point at infinity"));
  EXPECT_THAT(html, HasSubstr("capped at 1 px"));
  EXPECT_THAT(html, Not(HasSubstr(">10<")));  // the 10.8 px cell is capped
  // Without a grid there is no map.
  camcal["cameras"][0]["projection_uncertainty"].erase("grid");
  HtmlReport bare("t");
  AddCameraSection(TwoCameras(), camcal, "c.json", &bare);
  EXPECT_EQ(bare.figures(), 0);
}

TEST(CameraSectionsTest, WithoutCamcalJsonSaysWhereItComesFrom) {
  HtmlReport page("t");
  AddCameraSection(TwoCameras(), nlohmann::json(), "", &page);
  EXPECT_EQ(page.figures(), 0);
  EXPECT_THAT(page.Page(""), HasSubstr("kincal camcal --json"));
}

TEST(CameraSectionsTest, TrackingCountsFoundFramesAndRejectsOtherCsv) {
  const std::string path = ::testing::TempDir() + "kincal_points_test.csv";
  std::ofstream(path) << "frame,x,reproj_px,tags\n0,1.5,0.3,4\n1,,,0\n"
                         "2,1.6,0.2,5\n";
  HtmlReport page("t");
  AddTrackingSection(path, true, &page);
  EXPECT_EQ(page.figures(), 2);
  EXPECT_THAT(page.Page(""), HasSubstr("tip found in 2 of 3 frames"));
  std::ofstream(path) << "frame,y\n0,1\n";
  HtmlReport other("t");
  EXPECT_THROW(AddTrackingSection(path, true, &other), InputError);
  std::remove(path.c_str());
  HtmlReport missing("t");
  AddTrackingSection("nowhere/points.csv", false, &missing);
  EXPECT_THAT(missing.Page(""), HasSubstr("run kincal track"));
}

}  // namespace
}  // namespace kincal
