#include "camcal/cameramodel.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "data/error.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

// Written by mrcal 2.2 (cameramodel(...).write()), byte for byte.
const char* kMrcalOpencv8 = R"({
    'lensmodel':  'LENSMODEL_OPENCV8',

    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....
    'intrinsics': [ 1800.5, 1801.25, 639.5, 511.75, -0.2, 0.1, 0.001, -0.002, 0.01, 0.02, -0.01, 0.003,],

    # extrinsics are rt_fromref
    'extrinsics': [ 0.01, 0.02, -0.03, -0.12, 0.0005, 0.001,],

    'imagersize': [ 1280, 1024,],


}
)";

std::string ErrorOf(const std::string& text) {
  try {
    ParseCameraModel(text, "m.cameramodel");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

CameraIntrinsics Example(int num_distortion) {
  CameraIntrinsics in;
  in.width = 1280;
  in.height = 1024;
  in.fx = 1800.123456789;
  in.fy = 1801.987654321;
  in.cx = 640.3;
  in.cy = 511.7;
  const std::vector<double> all = {-0.21, 0.13,   0.0011, -0.0021,
                                   0.012, 0.0023, -0.011, 0.0031};
  in.distortion.assign(all.begin(), all.begin() + num_distortion);
  return in;
}

TEST(CameraModel, ReadsMrcalsFileAndProjectsAsMrcal) {
  const CameraModelFile m = ParseCameraModel(kMrcalOpencv8, "t8.cameramodel");
  EXPECT_EQ(m.intrinsics.width, 1280);
  EXPECT_EQ(m.intrinsics.height, 1024);
  ASSERT_EQ(m.intrinsics.distortion.size(), 8u);
  EXPECT_EQ(m.intrinsics.distortion[7], 0.003);
  // mrcal.project(np.array([0.3, -0.2, 1.5]), *m.intrinsics()) with mrcal 2.2.
  const Eigen::Vector2d px =
      Project(m.intrinsics, Eigen::Vector3d(0.3, -0.2, 1.5));
  EXPECT_NEAR(px.x(), 994.5682674399902, 1e-9);
  EXPECT_NEAR(px.y(), 274.90452828127826, 1e-9);
  // rt_cam_ref: p_in_cam = R(r) p_in_ref + t.
  const Eigen::Vector3d r(0.01, 0.02, -0.03);
  EXPECT_TRUE(m.cam_from_ref.R.isApprox(
      Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix(), 1e-15));
  EXPECT_EQ(m.cam_from_ref.t, Eigen::Vector3d(-0.12, 0.0005, 0.001));
  EXPECT_TRUE(m.valid_intrinsics_region.empty());
}

TEST(CameraModel, RoundTripProjectsIdenticallyForEveryModel) {
  for (int nd : {0, 4, 5, 8}) {
    CameraModelFile m;
    m.intrinsics = Example(nd);
    m.cam_from_ref.R =
        RotationMatrixFromVector(Eigen::Vector3d(0.1, -0.2, 0.3));
    m.cam_from_ref.t = Eigen::Vector3d(-120.25, 0.5, 1.0 / 3.0);
    m.valid_intrinsics_region = {{10, 10}, {1200, 12.5}, {640, 1000}, {10, 10}};
    const std::string text = CameraModelToText(m);
    EXPECT_THAT(text, HasSubstr("'lensmodel':  '" + MrcalLensModelName(nd)));
    EXPECT_THAT(text, HasSubstr("# written by kincal"));
    const CameraModelFile back = ParseCameraModel(text, "rt.cameramodel");
    EXPECT_EQ(back.intrinsics.distortion, m.intrinsics.distortion) << nd;
    EXPECT_EQ(back.intrinsics.fx, m.intrinsics.fx);
    EXPECT_EQ(back.cam_from_ref.t, m.cam_from_ref.t);
    EXPECT_EQ(back.valid_intrinsics_region, m.valid_intrinsics_region);
    for (const Eigen::Vector3d& p_in_ref :
         {Eigen::Vector3d(0.3, -0.2, 1.5), Eigen::Vector3d(-250, 180, 900)}) {
      const Eigen::Vector2d a =
          Project(m.intrinsics, m.cam_from_ref * p_in_ref);
      const Eigen::Vector2d b =
          Project(back.intrinsics, back.cam_from_ref * p_in_ref);
      EXPECT_LT((a - b).norm(), 1e-9) << nd;
    }
  }
}

TEST(CameraModel, AcceptsLegacyNamesCommentsAndUnusedKeys) {
  const CameraModelFile m = ParseCameraModel(
      "# a note\n{ 'distortion_model': 'DISTORTION_OPENCV4', # comment\n"
      "  \"intrinsics\": (500, 501, 319.5, 239.5, 0.1, -0.01, 0, 0),\n"
      "  'extrinsics': [0, 0, 0, 0, 0, 0],\n  'imagersize': [640, 480],\n"
      "  'icam_intrinsics': 0,\n  'optimization_inputs': b'a\\'b#{c',\n"
      "  'valid_intrinsics_region': [[0, 0], [639, 0], [639, 479], [0, 0]],\n"
      "}\n",
      "legacy.cameramodel");
  EXPECT_EQ(m.intrinsics.distortion.size(), 4u);
  EXPECT_EQ(m.intrinsics.fy, 501);
  EXPECT_EQ(m.valid_intrinsics_region.size(), 4u);
  EXPECT_TRUE(m.cam_from_ref.R.isIdentity());
}

TEST(CameraModel, RefusesUnsupportedLensModelsByName) {
  for (const std::string name :
       {"LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=100",
        "LENSMODEL_CAHVORE_linearity=0.00", "LENSMODEL_OPENCV12"}) {
    const std::string error = ErrorOf("{'lensmodel': '" + name +
                                      "', 'intrinsics': [1, 1, 0, 0], "
                                      "'extrinsics': [0,0,0,0,0,0], "
                                      "'imagersize': [640, 480]}");
    EXPECT_THAT(error, HasSubstr("m.cameramodel:1:15"));
    EXPECT_THAT(error, HasSubstr("lensmodel '" + name + "' is not supported"));
  }
}

TEST(CameraModel, BadFilesFailWithPlace) {
  const std::string ok_rest =
      "'extrinsics': [0,0,0,0,0,0], 'imagersize': [640, 480]}";
  EXPECT_THAT(ErrorOf("{'lensmodel': 'LENSMODEL_OPENCV5',\n 'intrinsics': [1, "
                      "1, 2, 2],\n" +
                      ok_rest),
              HasSubstr("m.cameramodel:2:16: intrinsics: LENSMODEL_OPENCV5 "
                        "has 9 numbers, got 4"));
  EXPECT_THAT(ErrorOf("{'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1, "
                      "1, 2, 2]}"),
              HasSubstr("missing key 'extrinsics'"));
  EXPECT_THAT(ErrorOf("{'lensmodel': 'LENSMODEL_PINHOLE',\n  'intrinsics': "
                      "[1 1, 2, 2], " +
                      ok_rest),
              HasSubstr("m.cameramodel:2:20: expected ',' or ']'"));
  EXPECT_THAT(ErrorOf("{'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [-1, "
                      "1, 2, 2], " +
                      ok_rest),
              HasSubstr("fx > 0"));
  EXPECT_THAT(ErrorOf("{'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1, "
                      "1, 2, 2], 'extrinsics': [0,0,0], 'imagersize': [640, "
                      "480]}"),
              HasSubstr("extrinsics: expected 6 numbers"));
  EXPECT_THAT(ErrorOf("{'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1, "
                      "1, 2, 2], 'extrinsics': [0,0,0,0,0,0], 'imagersize': "
                      "[640.5, 480]}"),
              HasSubstr("imagersize: expected [width, height]"));
  EXPECT_THAT(ErrorOf(""), HasSubstr("empty file"));
  EXPECT_THAT(ErrorOf("{'a': 1, 'a': 2}"), HasSubstr("duplicate key 'a'"));
  // A deep nest is refused with its place, not read until the stack ends
  // (a fuzzing finding: 100000 nested dicts).
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "{'a':";
  EXPECT_THAT(ErrorOf(deep),
              HasSubstr("m.cameramodel:1:161: containers nested over 32 "
                        "levels deep"));
}

TEST(CameraModel, RigFromModelsConvertsUnitsAndReference) {
  // Two cameras in metres relative to some reference (e.g. a board).
  CameraModelFile left, right;
  left.intrinsics = Example(5);
  right.intrinsics = Example(5);
  left.cam_from_ref.R = RotationMatrixFromVector(Eigen::Vector3d(0.1, 0, 0));
  left.cam_from_ref.t = Eigen::Vector3d(0.01, 0.02, 0.5);
  const Rigid3 right_from_left{
      RotationMatrixFromVector(Eigen::Vector3d(0, 0.05, 0)),
      Eigen::Vector3d(-0.12, 0.001, 0.002)};
  right.cam_from_ref = right_from_left * left.cam_from_ref;
  const Rig rig = RigFromCameraModels({{"left", left}, {"right", right}}, 1000);
  ASSERT_EQ(rig.cameras.size(), 2u);
  EXPECT_EQ(rig.cameras[0].intrinsics.name, "left");
  EXPECT_TRUE(rig.cameras[0].cam_from_rig.R.isIdentity());
  EXPECT_TRUE(rig.cameras[1].cam_from_rig.R.isApprox(right_from_left.R, 1e-14));
  EXPECT_LT(
      (rig.cameras[1].cam_from_rig.t - Eigen::Vector3d(-120, 1, 2)).norm(),
      1e-10);
  EXPECT_NEAR(rig.BaselineMm(), right_from_left.t.norm() * 1000, 1e-9);
  // And back: the models of the rig (reference = left camera) in metres.
  const std::vector<CameraModelFile> models = CameraModelsFromRig(rig, 1000);
  EXPECT_LT((models[1].cam_from_ref.t - right_from_left.t).norm(), 1e-15);
  EXPECT_THROW(RigFromCameraModels({{"a", left}, {"a", right}}, 1), InputError);
  EXPECT_THROW(RigFromCameraModels({{"a", left}}, 0), InputError);
}

}  // namespace
}  // namespace kincal
