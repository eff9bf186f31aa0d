#include "capture/joint_log.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "data/error.h"

namespace kincal::capture {
namespace {

// Stop-and-go as a robot program does it: still for an irregular dwell
// (1.5..2.7 s, so the stops are not periodic), then j1 moves by `step` deg
// at 10 deg/s and j2 by -step/2 deg; logged at 100 Hz from t0 on the
// controller clock.
struct Profile {
  double t0 = 1000.0;
  double step = 10.0;
  std::vector<double> starts;  // start of each dwell, from t0
  std::vector<double> dwells;
  Profile() {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> dwell(1.5, 2.7);
    double t = 0;
    for (int n = 0; n < 200; ++n) {
      starts.push_back(t);
      dwells.push_back(dwell(rng));
      t += dwells.back() + step / 10.0;
    }
  }
  void At(double t, double* j1, double* j2, double* speed) const {
    const double u = t - t0;
    const int n = static_cast<int>(
        std::upper_bound(starts.begin(), starts.end(), u) - starts.begin() - 1);
    const double dwell = dwells[n];
    const double r = u - starts[n];
    const double moved =
        r < dwell ? 0.0 : std::min(r - dwell, step / 10.0) * 10.0;
    *j1 = n * step + moved;
    *j2 = -0.5 * *j1;
    *speed = (r >= dwell) ? 10.0 : 0.0;
  }
};

std::string LogText(const Profile& p, double seconds) {
  std::ostringstream os;
  os << "# controller log\nt,j1,j2\n";
  os.precision(12);
  for (int i = 0; i <= static_cast<int>(seconds * 100); ++i) {
    const double t = p.t0 + i * 0.01;
    double a, b, s;
    p.At(t, &a, &b, &s);
    os << t << "," << a << "," << b << "\n";
  }
  return os.str();
}

TEST(JointLogTest, EstimatesTheClockOffsetFromStopsAndInterpolates) {
  const Profile p;
  const JointLog log = ParseJointLog(LogText(p, 100), "joints.csv", nullptr);
  ASSERT_EQ(log.names, (std::vector<std::string>{"j1", "j2"}));
  // Frames at 30 fps on another clock: frame time = log time + offset.
  const double offset = -987.6543;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.1);
  std::vector<double> times, motion;
  for (int k = 0; k < 1500; ++k) {  // 50 s
    const double tf = 20.0 + 5.0 / 30 + k / 30.0;
    times.push_back(tf);
    double a, b, s;
    // The change from the previous frame: the robot's motion half a frame
    // period earlier (and a little noise).
    p.At(tf - offset - 0.5 / 30, &a, &b, &s);
    motion.push_back((s > 0 ? 4.0 : 0.6) + noise(rng));
  }
  const JointMerge m = MergeJointLog(log, times, motion, {});
  EXPECT_TRUE(m.estimated);
  EXPECT_NEAR(m.offset_s, offset, 1.0 / 60);  // half a frame period
  EXPECT_GT(m.agreement, 0.97);
  EXPECT_GE(m.stops_matched, 14);  // ~16 stops in 50 s
  ASSERT_EQ(m.joints.size(), times.size());
  int still_checked = 0;
  for (size_t k = 0; k < times.size(); ++k) {
    double a, b, s;
    p.At(times[k] - offset, &a, &b, &s);
    if (s > 0) {
      // Moving at 10 deg/s > 1 deg/s: no reading (unless at the very edge
      // of a move, where the estimate may put it on the still side).
      continue;
    }
    double a2, b2, s2, a3, b3, s3;  // still well inside a still period
    p.At(times[k] - offset - 0.05, &a2, &b2, &s2);
    p.At(times[k] - offset + 0.05, &a3, &b3, &s3);
    if (s2 > 0 || s3 > 0) continue;
    ASSERT_FALSE(std::isnan(m.joints[k][0])) << k;
    EXPECT_NEAR(m.joints[k][0], a, 1e-9);
    EXPECT_NEAR(m.joints[k][1], b, 1e-9);
    ++still_checked;
  }
  EXPECT_GT(still_checked, 900);
  EXPECT_GT(m.too_fast, 200);
}

// Images whose stops are the log's, but which move again 0.6 s after each
// stop (something else moves in view): the stops fix an offset, yet the
// moving/still states agree in well under half the frames. Refused, with the
// offset and its agreement; a given offset is not checked.
TEST(JointLogTest, AChanceLevelOffsetIsRefused) {
  const Profile p;
  const JointLog log = ParseJointLog(LogText(p, 100), "joints.csv", nullptr);
  const double offset = -987.6543;
  std::vector<double> times, motion;
  for (int k = 0; k < 1500; ++k) {  // 50 s
    times.push_back(20.0 + 5.0 / 30 + k / 30.0);
    const double u = times.back() - offset - 0.5 / 30 - p.t0;
    const int n =
        static_cast<int>(std::upper_bound(p.starts.begin(), p.starts.end(), u) -
                         p.starts.begin() - 1);
    motion.push_back(u - p.starts[n] < 0.6 ? 0.6 : 4.0);
  }
  try {
    const JointMerge m = MergeJointLog(log, times, motion, {});
    FAIL() << "accepted an offset with agreement " << m.agreement;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("estimated clock offset"), std::string::npos) << what;
    EXPECT_NE(what.find("% of the frames"), std::string::npos) << what;
    EXPECT_NE(what.find("--joints-offset"), std::string::npos) << what;
  }
  // A given offset is the user's: no agreement check.
  JointMergeOptions given;
  given.offset_s = offset;
  EXPECT_NO_THROW(MergeJointLog(log, times, motion, given));
}

// A perfectly periodic program cannot tell its cycles apart: the estimate
// must refuse rather than pick one.
TEST(JointLogTest, PeriodicStopsAreAmbiguous) {
  std::ostringstream log_text, dummy;
  log_text << "t,a\n";
  for (int i = 0; i <= 3000; ++i) {  // 30 s: 1 s still, 1 s moving
    const double t = i * 0.01;
    const double r = std::fmod(t, 2.0);
    const double a = std::floor(t / 2.0) * 5 + (r < 1 ? 0 : (r - 1) * 5);
    log_text << t << "," << a << "\n";
  }
  const JointLog log = ParseJointLog(log_text.str(), "log", nullptr);
  std::vector<double> times, motion;
  for (int k = 0; k < 300; ++k) {  // 10 s at 30 fps, offset 100 - 7.3
    times.push_back(100 + k / 30.0);
    const double r = std::fmod(times.back() - 92.7, 2.0);
    motion.push_back(r < 1 ? 0.5 : 4.0);
  }
  try {
    MergeJointLog(log, times, motion, {});
    FAIL() << "expected an ambiguity error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ambiguous"), std::string::npos)
        << e.what();
  }
}

TEST(JointLogTest, GivenOffsetInterpolatesLinearly) {
  const JointLog log =
      ParseJointLog("t,a\n0,0\n0.5,1\n1.0,1\n", "log", nullptr);
  JointMergeOptions options;
  options.offset_s = 10.0;
  options.max_speed = 5.0;
  const JointMerge m = MergeJointLog(log, {10.0, 10.25, 10.75}, {}, options);
  EXPECT_FALSE(m.estimated);
  EXPECT_NEAR(m.joints[0][0], 0.0, 1e-12);
  EXPECT_NEAR(m.joints[1][0], 0.5, 1e-12);
  EXPECT_NEAR(m.joints[2][0], 1.0, 1e-12);
  options.max_speed = 1.0;  // 2 units/s is too fast
  const JointMerge slow = MergeJointLog(log, {10.25, 10.75}, {}, options);
  EXPECT_TRUE(std::isnan(slow.joints[0][0]));
  EXPECT_FALSE(std::isnan(slow.joints[1][0]));
}

void ExpectError(const std::string& text, const std::string& needle,
                 const std::vector<std::string>* names = nullptr) {
  try {
    ParseJointLog(text, "joints.csv", names);
    FAIL() << "expected InputError for: " << text;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << e.what();
  }
}

TEST(JointLogTest, MalformedLogsAreRejectedWithTheirLine) {
  ExpectError("a,b\n0,1\n", "'t' column");
  ExpectError("t,j1\n0,1\n0.1,x\n", "joints.csv:3:");
  ExpectError("t,j1\n0,1\n0.1\n", "expected 2 cells");
  ExpectError("t,j1\n0,1\n0.2,1\n0.1,1\n", "went backwards");
  ExpectError("t,j1\n0,1\n0.1,1\n5.1,1\n", "jumps by 5");
  ExpectError("t,j1\n0,1\n", "at least two rows");
  const std::vector<std::string> robot = {"j1", "j2"};
  ExpectError("t,j1,j9\n0,1,2\n0.1,1,2\n", "unknown joint 'j9'", &robot);
  ExpectError("t,j1\n0,1\n0.1,1\n", "missing the column of joint 'j2'", &robot);
}

TEST(JointLogTest, ALogThatDoesNotCoverTheSessionIsAnError) {
  const JointLog log =
      ParseJointLog("t,a\n0,0\n0.5,1\n1.0,1\n", "log", nullptr);
  JointMergeOptions options;
  options.offset_s = 0.0;
  EXPECT_THROW(MergeJointLog(log, {0.5, 1.5}, {}, options), InputError);
  // Estimating: a 1 s log cannot cover a 3 s session.
  EXPECT_THROW(MergeJointLog(log, {0, 1, 2, 3}, {0, 1, 0, 1}, {}), InputError);
}

TEST(JointLogTest, NoStopsMeansTheOffsetCannotBeEstimated) {
  const JointLog log =
      ParseJointLog("t,a\n0,0\n1,10\n2,20\n3,30\n4,40\n", "log", nullptr);
  try {
    MergeJointLog(log, {0.5, 1.0, 1.5}, {1, 1, 1}, {});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--joints-offset"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace kincal::capture
