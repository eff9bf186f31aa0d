// End to end, 1..N cameras through `kincal capture` (format v3, "Recorded
// session with N cameras"): a session rendered by `kincal simulate --render
// --render-cameras N` is replayed folder by folder through `kincal capture
// --camera NAME='folder:...'`, its joint readings given as a controller log
// (--joints); `kincal track --session` must then give the same tips and the
// same observations from the captured session as from the rendered one, and
// `kincal bundle --session` the same frames and reprojection RMS.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "data/atomic_file.h"
#include "tests/testing/csv_rows.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::ReadCsvRows;
using testing::RunKincal;
using testing::RunResult;

constexpr int kPoses = 8;

// A rendered session and what capture needs to replay it.
struct Rendered {
  std::string dir;                   // simulate's --out
  std::vector<std::string> cameras;  // frames.csv's t_<name> columns, in order
  std::vector<std::string> header;   // frames.csv's header
  int frames = 0;
  double period_s = 1;  // between frames (the folders replay at 1 / period)
  std::string mosaic;   // the images are raw mosaics of this pattern
};

// `kincal simulate --render` of BH-7 with `cameras` cameras, and a
// controller log dir/joints.csv of its joint readings on the session's
// clock: frame k's readings held (a row every 0.5 s: the log's largest step
// is 1 s) from a quarter second after the previous frame's half period to a
// quarter second before the next's, so the robot is still at every
// frame's time.
Rendered RenderWithJointLog(int cameras, bool raw_mosaic = false) {
  Rendered r;
  r.mosaic = raw_mosaic ? "RGGB" : "";
  r.dir = testing::MakeTempDir("capture_cameras") + "/sim";
  const RunResult sim = RunKincal(
      "simulate --robot " + testing::SourceDir() +
      "/data/robots/bh7.yaml --out " + r.dir + " --poses " +
      std::to_string(kPoses) +
      " --noise 0 --seed 3 --render --render-width 640 --render-height 512 "
      "--render-cameras " +
      std::to_string(cameras) + (raw_mosaic ? " --render-bayer-raw" : ""));
  EXPECT_EQ(sim.exit_code, 0) << sim.err;
  const auto rows = ReadCsvRows(r.dir + "/session/frames.csv");
  if (rows.empty()) return r;
  r.header = rows[0];
  std::vector<size_t> joint_columns;
  std::string log = "t";
  for (size_t c = 1; c < r.header.size(); ++c) {
    const std::string& h = r.header[c];
    if (h.rfind("t_", 0) == 0) {
      r.cameras.push_back(h.substr(2));
    } else if (h.rfind("seq_", 0) != 0) {
      joint_columns.push_back(c);
      log += "," + h;
    }
  }
  log += "\n";
  r.frames = static_cast<int>(rows.size()) - 1;
  if (r.frames < 2) return r;
  r.period_s = std::stod(rows[2][1]) - std::stod(rows[1][1]);  // t_<first>
  const double hold = r.period_s / 2 - 0.25;
  for (int k = 0; k < r.frames; ++k) {
    const double t = std::stod(rows[k + 1][1]);
    for (double dt = -hold; dt <= hold + 1e-9; dt += 0.5) {
      log += std::to_string(t + dt);
      for (size_t c : joint_columns) log += "," + rows[k + 1][c];
      log += "\n";
    }
  }
  WriteFileAtomic(r.dir + "/joints.csv", log);
  return r;
}

// `kincal capture` of the rendered session's folders into `out`, every
// camera named as in the rig, replayed at the rendered frame rate (so the
// frame times are the rendered ones).
RunResult CaptureReplay(const Rendered& r, const std::string& out) {
  std::string cameras;
  for (const std::string& c : r.cameras) {
    cameras += " --camera " + c + "='folder:" + r.dir + "/session/" + c +
               "/*.png?fps=" + std::to_string(1 / r.period_s) +
               (r.mosaic.empty() ? "" : "&mosaic=" + r.mosaic) + "'";
  }
  return RunKincal("capture" + cameras + " --out " + out + " --joints " +
                   r.dir + "/joints.csv --joints-offset 0 --robot " + r.dir +
                   "/robot.yaml --json");
}

// `kincal track --session` with the rendered rig: tips to `points`, the
// tips merged with the session's readings to `obs`.
void Track(const Rendered& r, const std::string& session,
           const std::string& points, const std::string& obs) {
  const RunResult t = RunKincal(
      "track --rig " + r.dir + "/rig.yaml --target " + r.dir +
      "/target.yaml --session " + session + " --robot " + r.dir +
      "/robot.yaml --out " + points + " --out-obs " + obs + " --quiet --json");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const auto j = nlohmann::json::parse(t.out);
  EXPECT_EQ(j["frames"], r.frames);
  EXPECT_GE(j["found"].get<int>(), r.frames / 2);  // tips to compare
}

// `kincal bundle --session` with the rendered robot, rig and target.
nlohmann::json Bundle(const Rendered& r, const std::string& session,
                      const std::string& out) {
  const RunResult b =
      RunKincal("bundle --robot " + r.dir + "/robot.yaml --rig " + r.dir +
                "/rig.yaml --target " + r.dir + "/target.yaml --session " +
                session + " --quiet --out " + out + " --json");
  EXPECT_EQ(b.exit_code, 0) << b.err;
  return b.exit_code == 0 ? nlohmann::json::parse(b.out) : nlohmann::json();
}

// Same header, same rows; numbers equal to 1e-9 relative (joint readings
// pass through the log and frames.csv as text, 10 digits), other cells
// identical.
void ExpectSameCsv(const std::string& a, const std::string& b) {
  const auto ra = ReadCsvRows(a);
  const auto rb = ReadCsvRows(b);
  ASSERT_EQ(ra.size(), rb.size()) << a << " vs " << b;
  ASSERT_GT(ra.size(), 1u) << a;
  EXPECT_EQ(ra[0], rb[0]);
  int numbers = 0;
  for (size_t i = 1; i < ra.size(); ++i) {
    ASSERT_EQ(ra[i].size(), rb[i].size()) << "row " << i;
    for (size_t c = 0; c < ra[i].size(); ++c) {
      char* end_a = nullptr;
      char* end_b = nullptr;
      const double va = std::strtod(ra[i][c].c_str(), &end_a);
      const double vb = std::strtod(rb[i][c].c_str(), &end_b);
      if (ra[i][c].empty() || *end_a != '\0' || *end_b != '\0') {
        EXPECT_EQ(ra[i][c], rb[i][c]) << "row " << i << " column " << c;
        continue;
      }
      ++numbers;
      EXPECT_NEAR(va, vb, 1e-9 * std::max(1.0, std::abs(va)))
          << a << " row " << i << " column " << ra[0][c];
    }
  }
  EXPECT_GT(numbers, 0);
}

// Replays `r` through capture and checks the captured session against the
// rendered one: layout, frames.csv header, capture's JSON, track and bundle.
void CaptureAndCompare(const Rendered& r) {
  ASSERT_EQ(r.frames, kPoses);
  const std::string out = r.dir + "/captured";
  const RunResult c = CaptureReplay(r, out);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const auto j = nlohmann::json::parse(c.out);
  EXPECT_EQ(j["frames"], r.frames);
  EXPECT_EQ(j["pairing"], "lockstep");
  EXPECT_EQ(j["length_mismatch"], false);
  EXPECT_EQ(j["joints"]["frames_with_reading"], r.frames);
  ASSERT_EQ(j["cameras"].size(), r.cameras.size());
  for (size_t k = 0; k < r.cameras.size(); ++k) {
    EXPECT_EQ(j["cameras"][k]["name"], r.cameras[k]);
    EXPECT_EQ(j["cameras"][k]["dropped"], 0);
    EXPECT_NE(j["cameras"][k]["uri"].get<std::string>().find(r.cameras[k]),
              std::string::npos);
    EXPECT_TRUE(testing::Exists(out + "/" + r.cameras[k] + "/000007.png"));
    EXPECT_EQ(j["cameras"][k].value("mosaic", ""), r.mosaic);
  }
  // Left/right fields only for a pair.
  EXPECT_EQ(j.contains("dropped_left"), r.cameras.size() == 2);
  EXPECT_EQ(ReadCsvRows(out + "/frames.csv")[0], r.header);

  Track(r, r.dir + "/session", r.dir + "/points_rendered.csv",
        r.dir + "/obs_rendered.csv");
  Track(r, out, r.dir + "/points_captured.csv", r.dir + "/obs_captured.csv");
  ExpectSameCsv(r.dir + "/points_rendered.csv", r.dir + "/points_captured.csv");
  ExpectSameCsv(r.dir + "/obs_rendered.csv", r.dir + "/obs_captured.csv");

  // The bundle sees the same corners at the same readings (the readings
  // went through 10-digit text, hence the relative 1e-4).
  const auto b1 = Bundle(r, r.dir + "/session", r.dir + "/cal_rendered.yaml");
  const auto b2 = Bundle(r, out, r.dir + "/cal_captured.yaml");
  ASSERT_TRUE(b1.contains("used_frames") && b2.contains("used_frames"));
  EXPECT_GT(b1["used_frames"].get<int>(), 0);
  EXPECT_EQ(b1["used_frames"], b2["used_frames"]);
  const double rms = b1["reproj_rms_px"].get<double>();
  EXPECT_NEAR(b2["reproj_rms_px"].get<double>(), rms, 1e-4 * rms);
}

// A colour camera's raw mosaic replayed with mosaic=RGGB: session.yaml
// records it, and track and bundle read the captured session as raw
// mosaics without --bayer, alike with the rendered one (which records it
// too).
TEST(CaptureCamerasCli, RawMosaicCamerasReplayIntoASessionTrackAndBundleAlike) {
  const Rendered r = RenderWithJointLog(2, true);
  CaptureAndCompare(r);
  std::ifstream yaml(r.dir + "/captured/session.yaml");
  std::stringstream text;
  text << yaml.rdbuf();
  EXPECT_NE(text.str().find("mosaic: RGGB"), std::string::npos) << text.str();
  // Read as raw, not as gray: no warning that the images look like a mosaic.
  const RunResult t =
      RunKincal("track --rig " + r.dir + "/rig.yaml --target " + r.dir +
                "/target.yaml --session " + r.dir + "/captured --out " + r.dir +
                "/p.csv --quiet --json");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_EQ(t.out.find("images_look_raw_bayer"), std::string::npos) << t.out;
  EXPECT_NE(t.err.find("raw RGGB mosaics"), std::string::npos) << t.err;
}

TEST(CaptureCamerasCli, ThreeCamerasReplayIntoASessionTrackAndBundleReadAlike) {
  const Rendered r = RenderWithJointLog(3);
  ASSERT_EQ(r.cameras.size(), 3u);
  CaptureAndCompare(r);
}

TEST(CaptureCamerasCli, OneCameraReplaysIntoASessionTrackAndBundleReadAlike) {
  const Rendered r = RenderWithJointLog(1);
  ASSERT_EQ(r.cameras.size(), 1u);
  CaptureAndCompare(r);
}

TEST(CaptureCamerasCli, TextOutputNamesTheCamerasAndTheTrackCommand) {
  const std::string dir = testing::MakeTempDir("capture_cameras_text");
  // Three two-frame recordings.
  for (const char* cam : {"a", "b", "c"}) {
    testing::RunShell("mkdir -p " + dir + "/" + cam);
    for (int k = 0; k < 2; ++k) {
      cv::imwrite(dir + "/" + cam + "/" + std::to_string(k) + ".png",
                  cv::Mat(12, 16, CV_8UC1, cv::Scalar(40 * k)));
    }
  }
  const RunResult c = RunKincal("capture --camera a='folder:" + dir +
                                "/a/*.png' --camera b='folder:" + dir +
                                "/b/*.png' --camera c='folder:" + dir +
                                "/c/*.png' --out " + dir + "/s");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_NE(c.out.find("recorded 2 frame sets (3 cameras)"), std::string::npos)
      << c.out;
  EXPECT_NE(c.out.find("dropped a 0, b 0, c 0"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("kincal track --rig RIG.yaml --target TARGET.yaml "
                       "--session '" +
                       dir + "/s'"),
            std::string::npos)
      << c.out;
}

TEST(CaptureCamerasCli, BadCameraListsExit2AndWriteNothing) {
  const std::string dir = testing::MakeTempDir("capture_cameras_bad");
  testing::RunShell("mkdir -p " + dir + "/a");
  const std::string src = "'folder:" + dir + "/a/*.png'";
  const std::string fake = "'fake:x'";
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"--camera a=" + fake + " --camera a='fake:y'", "given twice"},
      {"--camera 'my cam'=" + fake, "my cam"},
      {"--camera a=" + fake + " --camera b=" + fake, "same source"},
      {"--camera a=" + fake + " --camera b=" + src,
       "cannot pair a camera with a recording"},
      {"--camera a=" + fake + " --left " + fake, "replaces --left/--right"},
      {"--left " + fake, "--right is required with --left"},
  };
  for (const Case& k : cases) {
    const RunResult r =
        RunKincal("capture " + k.args + " --out " + dir + "/s --frames 1");
    EXPECT_EQ(r.exit_code, 2) << k.args << "\n" << r.err;
    EXPECT_NE(r.err.find(k.message), std::string::npos) << k.args << r.err;
    EXPECT_FALSE(testing::Exists(dir + "/s")) << k.args;
  }
}

}  // namespace
}  // namespace kincal
