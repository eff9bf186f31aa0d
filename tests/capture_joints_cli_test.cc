// End to end: `kincal capture --joints joints.csv --robot robot.yaml` on a
// replayed recording whose images move when the logged robot moves: the
// clock offset is estimated from the stops, still frames get the logged
// joint values, moving frames none; bad logs exit 2.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

constexpr double kFps = 30;
constexpr int kFrames = 450;           // 15 s
constexpr double kLogStart = 5000.0;   // controller clock
constexpr double kOffset = -5002.266;  // frame (media) time = log + offset

// Irregular stop-and-go of two joints (deg), 10 deg/s moves of 8 deg.
struct Program {
  std::vector<double> starts, dwells;
  Program() {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> dwell(0.8, 1.6);
    double t = 0;
    for (int n = 0; n < 40; ++n) {
      starts.push_back(t);
      dwells.push_back(dwell(rng));
      t += dwells.back() + 0.8;
    }
  }
  // Returns the joint values and whether the robot moves at log time t.
  bool At(double t, double* j1, double* j2) const {
    const double u = t - kLogStart;
    const int n = static_cast<int>(
        std::upper_bound(starts.begin(), starts.end(), u) - starts.begin() - 1);
    const double r = u - starts[n];
    const double moved =
        r < dwells[n] ? 0.0 : std::min(r - dwells[n], 0.8) * 10;
    *j1 = 8.0 * n + moved;
    *j2 = 30 - 0.5 * *j1;
    return r >= dwells[n] && r < dwells[n] + 0.8;
  }
};

struct Fixture {
  std::string dir, robot, log;
};

Fixture Make(const std::string& tag, const std::string& log_header = "t,j1,j2",
             double log_seconds = 40) {
  Fixture f;
  f.dir = testing::MakeTempDir(tag);
  const Program program;
  std::mt19937 rng(1);
  for (int k = 0; k < kFrames; ++k) {
    double j1, j2;
    program.At(k / kFps - kOffset, &j1, &j2);
    cv::Mat img(120, 320, CV_8UC1, cv::Scalar(90));
    cv::rectangle(img, cv::Rect(static_cast<int>(j1 * 4) % 280, 30, 24, 40),
                  cv::Scalar(220), cv::FILLED);
    cv::Mat noise(img.size(), CV_8UC1);
    cv::randu(noise, 0, 3);
    img += noise;
    char name[64];
    std::snprintf(name, sizeof(name), "/l_%04d.png", k);
    cv::imwrite(f.dir + name, img);
    std::snprintf(name, sizeof(name), "/r_%04d.png", k);
    cv::imwrite(f.dir + name, img);
  }
  std::ostringstream log;
  log.precision(12);
  log << log_header << "\n";
  for (int i = 0; i <= static_cast<int>(log_seconds * 125); ++i) {  // 125 Hz
    const double t = kLogStart + i / 125.0;
    double j1, j2;
    program.At(t, &j1, &j2);
    log << t << "," << j1 << "," << j2 << "\n";
  }
  f.log = f.dir + "/joints.csv";
  WriteFileAtomic(f.log, log.str());
  f.robot = f.dir + "/robot.yaml";
  WriteFileAtomic(f.robot,
                  "kincal_robot: 1\nname: two\nconvention: dh\njoints:\n"
                  "  - {name: j1, type: revolute, d: 0, alpha: 0, a: 300, "
                  "theta: 0, limits: [-10, 400]}\n"
                  "  - {name: j2, type: revolute, d: 0, alpha: 0, a: 200, "
                  "theta: 0, limits: [-200, 90]}\n"
                  "tool: {d: 0, alpha: 0, a: 50, theta: 0}\n");
  return f;
}

std::string Capture(const Fixture& f, const std::string& out,
                    const std::string& extra = "") {
  return "capture --left 'folder:" + f.dir +
         "/l_*.png' --right 'folder:" + f.dir + "/r_*.png' --out " + out +
         " --joints " + f.log + " --robot " + f.robot + " --json " + extra;
}

TEST(CaptureJointsCli, MergesTheLogWithAnEstimatedClockOffset) {
  const Fixture f = Make("capj");
  const std::string out = f.dir + "/session";
  const RunResult r = RunKincal(Capture(f, out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], kFrames);
  EXPECT_TRUE(j["joints"]["offset_estimated"].get<bool>());
  // The stated tolerance: half a frame period.
  EXPECT_NEAR(j["joints"]["offset_s"].get<double>(), kOffset, 0.5 / kFps);
  const auto lines = TokenizeCsv(ReadFile(out + "/frames.csv"), "frames.csv");
  ASSERT_EQ(lines.size(), kFrames + 1u);
  ASSERT_EQ(lines[0].fields.size(), 7u);
  EXPECT_EQ(lines[0].fields[5].text, "j1");
  EXPECT_EQ(lines[0].fields[6].text, "j2");
  const Program program;
  int settled = 0, settled_with_reading = 0, moving_with_reading = 0;
  for (int k = 0; k < kFrames; ++k) {
    const auto& cells = lines[k + 1].fields;
    const double t = k / kFps - kOffset;
    double j1, j2, a, b;
    const bool moving = program.At(t, &j1, &j2);
    // Settled: still for 0.1 s either side.
    const bool settled_here =
        !moving && !program.At(t - 0.1, &a, &b) && !program.At(t + 0.1, &a, &b);
    if (settled_here) {
      ++settled;
      if (!cells[5].text.empty()) {
        ++settled_with_reading;
        EXPECT_NEAR(std::stod(cells[5].text), j1, 1e-6) << k;
        EXPECT_NEAR(std::stod(cells[6].text), j2, 1e-6) << k;
      }
    }
    const bool mid_move =
        moving && program.At(t - 0.05, &a, &b) && program.At(t + 0.05, &a, &b);
    if (mid_move && !cells[5].text.empty()) ++moving_with_reading;
  }
  EXPECT_GT(settled, 200);
  EXPECT_EQ(settled_with_reading, settled);  // every settled frame
  EXPECT_EQ(moving_with_reading, 0);
}

TEST(CaptureJointsCli, UnknownJointNameIsBadInputAndWritesNothing) {
  const Fixture f = Make("capj_unknown", "t,j1,elbow");
  const std::string out = f.dir + "/session";
  const RunResult r = RunKincal(Capture(f, out));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown joint 'elbow'"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(out));
}

TEST(CaptureJointsCli, ALogThatDoesNotCoverTheSessionKeepsTheSession) {
  const Fixture f = Make("capj_short", "t,j1,j2", 10);  // 10 s for 15 s
  const std::string out = f.dir + "/session";
  const RunResult r = RunKincal(Capture(f, out, "--joints-offset -5002.3"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("does not cover"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("kept"), std::string::npos) << r.err;
  // Session kept, complete, without joint columns.
  const auto lines = TokenizeCsv(ReadFile(out + "/frames.csv"), "frames.csv");
  EXPECT_EQ(lines.size(), kFrames + 1u);
  EXPECT_EQ(lines[0].fields.size(), 5u);
}

}  // namespace
}  // namespace kincal
