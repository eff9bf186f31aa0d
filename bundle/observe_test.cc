#include "bundle/observe.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "data/session.h"
#include "synth/recorded_session.h"
#include "synth/render.h"

namespace kincal {
namespace {

// An empty path under the temporary directory, one per test and run.
std::string FreshDir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("kincal_observe_" + name + "_" +
       std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::remove_all(dir);
  return dir.string();
}

// A rendered three-frame session: the second frame has no joint readings.
TEST(ObserveSession, DetectsTheToolInEveryFrameWithJoints) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RecordedSessionInput in;
  in.rig_from_tool = {ExampleToolPose(0), ExampleToolPose(1),
                      ExampleToolPose(2)};
  in.joint_names = {"j1", "j2"};
  in.joints = {{10, 20}, {}, {30, 40}};
  const std::string dir = FreshDir("frames");
  RenderRecordedSession(rig, target, in, RenderOptions(), 1, dir);
  SessionReadOptions so;
  so.joint_names = in.joint_names;
  const Session session = ReadSession(dir, so);
  std::vector<int> progress;
  ObserveOptions oo;
  oo.progress = [&](int done, int total) {
    EXPECT_EQ(total, 2);
    progress.push_back(done);
  };
  const SessionObservations obs = ObserveSession(session, rig, target, oo);
  std::filesystem::remove_all(dir);

  EXPECT_EQ(obs.session_frames, 3);
  EXPECT_EQ(obs.without_joints, 1);
  EXPECT_EQ(obs.without_tags, 0);
  EXPECT_EQ(progress.back(), 2);
  ASSERT_EQ(obs.frames.size(), 2u);
  const int truth_index[2] = {0, 2};
  for (int k = 0; k < 2; ++k) {
    const BundleFrame& f = obs.frames[k];
    EXPECT_EQ(f.frame, truth_index[k]);
    EXPECT_EQ(f.q_reading, in.joints[truth_index[k]]);
    ASSERT_TRUE(f.tracked) << k;
    const Rigid3& truth = in.rig_from_tool[truth_index[k]];
    EXPECT_LT((f.rig_from_tool.t - truth.t).norm(), 1.0) << k;
    EXPECT_LT(f.tracked_rms_px, 0.5) << k;
    // At least a camera's worth of corners, each near its projection.
    EXPECT_GE(f.corners.size(), 4 * target.tags.size()) << k;
    for (const BundleCorner& c : f.corners) {
      const Camera& cam = rig.cameras[c.camera];
      const Eigen::Vector2d expected =
          Project(cam.intrinsics,
                  cam.cam_from_rig *
                      (truth * target.tags[c.tag].CornerInTool(c.corner)));
      EXPECT_LT((c.px - expected).norm(), 0.5);
    }
  }
}

// A colour camera's demosaiced images are told from gray ones (the
// bundle's warning images_demosaiced); read as a raw mosaic they are not
// checked.
TEST(ObserveSession, TellsDemosaicedImagesFromGray) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RecordedSessionInput in;
  in.rig_from_tool = {ExampleToolPose(0), ExampleToolPose(1)};
  in.joint_names = {"j1", "j2"};
  in.joints = {{10, 20}, {30, 40}};
  const std::string dir = FreshDir("bayer");
  SessionReadOptions so;
  so.joint_names = in.joint_names;
  int demosaiced[2] = {0, 0};
  for (const bool bayer : {false, true}) {
    std::filesystem::remove_all(dir);
    RenderOptions ro;
    ro.bayer = bayer;
    RenderRecordedSession(rig, target, in, ro, 1, dir);
    const SessionObservations obs =
        ObserveSession(ReadSession(dir, so), rig, target, ObserveOptions());
    demosaiced[bayer] = obs.looks_demosaiced;
    ASSERT_EQ(obs.frames.size(), 2u);
    EXPECT_TRUE(obs.frames[0].tracked) << bayer;
  }
  std::filesystem::remove_all(dir);
  EXPECT_EQ(demosaiced[0], 0);
  EXPECT_EQ(demosaiced[1], 2);
}

TEST(ObserveSession, CornerWeightFollowsTheTagsContrast) {
  ObserveOptions o;  // full weight from 100 gray levels, at least 0.1
  EXPECT_DOUBLE_EQ(CornerWeight(150, o), 1.0);
  EXPECT_DOUBLE_EQ(CornerWeight(100, o), 1.0);
  EXPECT_DOUBLE_EQ(CornerWeight(50, o), 0.5);
  EXPECT_DOUBLE_EQ(CornerWeight(4, o), 0.1);
  o.full_weight_contrast = 0;
  EXPECT_DOUBLE_EQ(CornerWeight(4, o), 1.0);
}

}  // namespace
}  // namespace kincal
