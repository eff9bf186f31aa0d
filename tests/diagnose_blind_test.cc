// Blind end-to-end suite of `kincal diagnose model`: a seeded generator
// hides one effect (cause, joint, magnitude in a detectable range, noise
// level, pose count, robot) in simulated data, or none; the diagnosis runs
// through the public commands (`kincal simulate` -> `kincal diagnose model
// --json`) without knowing the answer; the test asserts the named cause and
// joint and the magnitude within 25 %, and `no_significant_effect` on null
// cases. Misses and false positives are counted and printed.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

struct RobotSpec {
  std::string file;
  std::vector<std::string> joints;      // joints whose errors move the tip
  std::vector<std::string> revolute;    // cyclic applies
  std::vector<std::string> compliance;  // gravity torque varies about them
  std::vector<std::string> tilt;        // nominally parallel to the previous
};

const std::vector<RobotSpec>& Robots() {
  static const std::vector<RobotSpec> robots = {
      {"bh7.yaml",
       {"j1", "j2", "j3", "j4", "j5"},
       {"j2", "j3", "j4", "j5"},
       {"j5"},
       {"j2", "j3", "j4"}},
      // The UR10's tracker target sits on the wrist_3 axis (tool row d only):
      // wrist_3 errors do not move the measured point, so it is no case.
      {"ur10.yaml",
       {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
        "wrist_1_joint", "wrist_2_joint"},
       {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
        "wrist_1_joint", "wrist_2_joint"},
       {"shoulder_lift_joint", "elbow_joint", "wrist_1_joint"},
       {"elbow_joint", "wrist_1_joint"}},
  };
  return robots;
}

struct Case {
  int robot = 0;
  std::string cause;  // "" = null case
  std::string joint;
  double magnitude = 0.0;
  double noise_mm = 0.03;
  int poses = 240;
  uint64_t seed = 1;

  std::string Effect() const {
    std::ostringstream os;
    os << cause << ":";
    if (!joint.empty()) os << joint << ":";
    os << magnitude;
    return os.str();
  }
};

// Seeded generator: every cause (and the null case) three times, robot,
// joint, magnitude, noise and pose count at random.
std::vector<Case> MakeCases(uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  auto pick = [&](const std::vector<std::string>& v) {
    return v[std::uniform_int_distribution<size_t>(0, v.size() - 1)(rng)];
  };
  std::vector<std::string> causes;
  for (int rep = 0; rep < 3; ++rep) {
    for (const char* c : {"", "backlash", "compliance", "cyclic", "gain",
                          "axis_tilt", "drift"}) {
      causes.push_back(c);
    }
  }
  causes.push_back("");
  causes.push_back("backlash");
  causes.push_back("cyclic");
  std::shuffle(causes.begin(), causes.end(), rng);
  std::vector<Case> cases;
  for (const std::string& cause : causes) {
    Case c;
    c.robot = uniform(0, 1) < 0.7 ? 0 : 1;
    const RobotSpec& r = Robots()[c.robot];
    c.cause = cause;
    c.noise_mm = uniform(0.01, 0.05);
    c.poses = static_cast<int>(uniform(120, 300));
    c.seed = std::uniform_int_distribution<uint64_t>(1, 1u << 30)(rng);
    if (cause == "backlash") {
      c.joint = pick(r.joints);
      c.magnitude = uniform(0.05, 0.3);
    } else if (cause == "compliance") {
      c.joint = pick(r.compliance);
      c.magnitude = uniform(0.05, 0.3);
    } else if (cause == "cyclic") {
      c.joint = pick(r.revolute);
      c.magnitude = uniform(0.05, 0.3);
    } else if (cause == "gain") {
      c.joint = pick(r.joints);
      c.magnitude = uniform(0.001, 0.005);
    } else if (cause == "axis_tilt") {
      c.joint = pick(r.tilt);
      c.magnitude = uniform(0.05, 0.3);
    } else if (cause == "drift") {
      c.magnitude = uniform(0.5, 3.0);
    }
    cases.push_back(c);
  }
  return cases;
}

TEST(DiagnoseBlindTest, NamesTheHiddenEffect) {
  // KINCAL_BLIND_SEED draws another suite (CI uses the fixed default).
  const char* env = std::getenv("KINCAL_BLIND_SEED");
  const uint64_t seed = env ? std::strtoull(env, nullptr, 10) : 20240611;
  const std::vector<Case> cases = MakeCases(seed);
  ASSERT_GE(cases.size(), 20u);
  const std::string dir = testing::MakeTempDir("diagnose_blind");
  ASSERT_FALSE(dir.empty());
  int hits = 0, misses = 0, false_positives = 0, nulls = 0, effects = 0;
  std::ostringstream table;
  for (size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const std::string sub = dir + "/case" + std::to_string(i);
    std::ostringstream sim;
    sim << "simulate --robot " << testing::SourceDir() << "/data/robots/"
        << Robots()[c.robot].file << " --out " << sub << " --poses " << c.poses
        << " --noise " << c.noise_mm << " --seed " << c.seed;
    if (!c.cause.empty()) sim << " --effect " << c.Effect();
    ASSERT_EQ(RunKincal(sim.str()).exit_code, 0) << sim.str();
    // Blind: only the nominal robot and the observations go in.
    const RunResult d =
        RunKincal("diagnose model --robot " + sub + "/robot.yaml --obs " + sub +
                  "/observations.csv --json");
    ASSERT_EQ(d.exit_code, 0) << sim.str();
    const nlohmann::json j = nlohmann::json::parse(d.out);
    ASSERT_TRUE(j.contains("verdict"));
    ASSERT_TRUE(j.contains("findings"));
    ASSERT_TRUE(j["nominal"].contains("heldout_rms_mm"));
    ASSERT_TRUE(j["final"].contains("heldout_rms_mm"));
    std::string named = "-";
    double magnitude = 0;
    if (!j["findings"].empty()) {
      const auto& f = j["findings"][0];
      named = f["cause"].get<std::string>() + ":" +
              (f["joint"].is_null() ? "" : f["joint"].get<std::string>());
      magnitude = f["magnitude"].is_null() ? 0.0 : f["magnitude"].get<double>();
    }
    bool ok = false;
    if (c.cause.empty()) {
      ++nulls;
      ok = j["verdict"] == "no_significant_effect";
      if (!ok) ++false_positives;
      EXPECT_TRUE(ok) << "case " << i << " null (" << sim.str()
                      << ") diagnosed " << named;
    } else {
      ++effects;
      ok = j["verdict"] == "effect_found" && named == c.cause + ":" + c.joint &&
           std::abs(std::abs(magnitude) - c.magnitude) <= 0.25 * c.magnitude;
      if (!ok) ++misses;
      EXPECT_TRUE(ok) << "case " << i << " hid " << c.Effect() << " ("
                      << sim.str() << "), diagnosed " << named << " "
                      << magnitude << "\n"
                      << d.out;
    }
    if (ok && !c.cause.empty()) ++hits;
    char line[256];
    std::snprintf(
        line, sizeof(line),
        "  %2zu %-10s %-34s noise %.3f poses %3d -> %-32s %10.5g %s\n", i,
        Robots()[c.robot].file.c_str(),
        c.cause.empty() ? "(none)" : c.Effect().c_str(), c.noise_mm, c.poses,
        named.c_str(), magnitude, ok ? "ok" : "WRONG");
    table << line;
  }
  std::printf("diagnose blind suite: %zu cases\n%s", cases.size(),
              table.str().c_str());
  std::printf(
      "diagnose blind suite: %d/%d effects named (misses %d), %d/%d null "
      "cases with a false positive\n",
      hits, effects, misses, false_positives, nulls);
}

TEST(DiagnoseBlindTest, BadInputExitsTwoAndWritesNothing) {
  const std::string dir = testing::MakeTempDir("diagnose_bad");
  ASSERT_EQ(
      RunKincal("simulate --robot " + testing::SourceDir() +
                "/data/robots/bh7.yaml --out " + dir + "/s --poses 1 --seed 3")
          .exit_code,
      0);
  const RunResult one =
      RunKincal("diagnose model --robot " + dir + "/s/robot.yaml --obs " + dir +
                "/s/observations.csv --json --out " + dir + "/cal.yaml");
  EXPECT_EQ(one.exit_code, 2);
  EXPECT_FALSE(testing::Exists(dir + "/cal.yaml"));
  EXPECT_NE(one.err.find("pose"), std::string::npos) << one.err;
  EXPECT_EQ(RunKincal("diagnose model --robot " + dir + "/s/robot.yaml --obs " +
                      dir + "/missing.csv")
                .exit_code,
            2);
  EXPECT_EQ(
      RunKincal("diagnose clearance --robot " + dir + "/s/robot.yaml --obs " +
                dir + "/s/observations.csv --gamma -1")
          .exit_code,
      2);
}

TEST(DiagnoseBlindTest, ClearanceAndCompareCommands) {
  const std::string dir = testing::MakeTempDir("diagnose_cmds");
  const std::string bh7 = testing::SourceDir() + "/data/robots/bh7.yaml";
  ASSERT_EQ(RunKincal("simulate --robot " + bh7 + " --out " + dir +
                      "/a --poses 120 --effect backlash:j3:1.0 --seed 8")
                .exit_code,
            0);
  ASSERT_EQ(RunKincal("simulate --robot " + bh7 + " --out " + dir +
                      "/b --poses 120 --seed 9")
                .exit_code,
            0);
  const RunResult c =
      RunKincal("diagnose clearance --robot " + dir + "/a/robot.yaml --obs " +
                dir + "/a/observations.csv --gamma 3 --json --plot " + dir +
                "/c.svg --csv " + dir + "/c.csv");
  ASSERT_EQ(c.exit_code, 0);
  const nlohmann::json jc = nlohmann::json::parse(c.out);
  EXPECT_TRUE(jc.contains("worst_pose"));
  ASSERT_EQ(jc["joints"].size(), 5u);
  for (const auto& joint : jc["joints"]) {
    EXPECT_TRUE(joint.contains("joint") && joint.contains("error_before_mm") &&
                joint.contains("error_min_mm") && joint.contains("at_offset"));
  }
  EXPECT_TRUE(jc.contains("suspect"));
  EXPECT_TRUE(jc.contains("command"));
  EXPECT_TRUE(testing::Exists(dir + "/c.svg"));
  EXPECT_TRUE(testing::Exists(dir + "/c.csv"));

  const RunResult p =
      RunKincal("diagnose compare " + dir + "/a/observations.csv " + dir +
                "/b/observations.csv --robot " + bh7 + " --json");
  ASSERT_EQ(p.exit_code, 0);
  const nlohmann::json jp = nlohmann::json::parse(p.out);
  EXPECT_EQ(jp["verdict"], "changed");
  EXPECT_TRUE(jp["joints"][2]["changed"].get<bool>());
  EXPECT_NEAR(jp["joints"][2]["before"]["clearance"].get<double>(), 1.0, 0.1);
}

}  // namespace
}  // namespace kincal
