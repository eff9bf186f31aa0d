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
#include "tests/testing/joint_log_session.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

using testing::JointLogSession;
using testing::JointLogSessionOptions;
using testing::kFps;
using testing::kFrames;
using testing::kOffset;
using Program = testing::StopAndGo;
using Fixture = JointLogSession;

Fixture Make(const std::string& tag, const std::string& log_header = "t,j1,j2",
             double log_seconds = 40) {
  JointLogSessionOptions options;
  options.log_header = log_header;
  options.log_seconds = log_seconds;
  return testing::MakeJointLogSession(tag, Program(), Program(), options);
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
