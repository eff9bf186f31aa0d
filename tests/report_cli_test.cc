// kincal report end to end: sections follow the inputs, the page is one
// self-contained file, and headless Chromium opens it without console
// errors with every figure drawn (a screenshot is kept in the build folder:
// build/report_demo.png). Skips the browser part when chromium is absent.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "data/atomic_file.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using ::testing::Contains;
using testing::Exists;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::RunKincal;
using testing::RunShell;

const char kChromium[] = "/usr/bin/chromium";

// Headless Chromium now and then never exits after a screenshot (seen once
// in ~40 runs, with another Chromium running): every call is bounded by
// `timeout` and retried once, so a hang costs a minute, not the CI job.
std::string ChromiumFlags(const std::string& profile) {
  return "timeout -k 5 60 " + std::string(kChromium) +
         " --headless --no-sandbox --disable-gpu --disable-quic "
         "--no-first-run --disable-background-networking "
         "--disable-component-update --disable-sync --user-data-dir=" +
         profile + " ";
}

std::vector<std::string> Sections(const nlohmann::json& j) {
  return j["sections"].get<std::vector<std::string>>();
}

// Opens the page in headless Chromium: console errors, figures drawn, and a
// screenshot at `png`.
void CheckInBrowser(const std::string& html, int figures,
                    const std::string& png) {
  if (!Exists(kChromium)) {
    GTEST_SKIP() << kChromium << " not installed: browser check skipped "
                 << "(apt-get install chromium)";
  }
  const std::string dir = testing::MakeTempDir("chromium");
  auto run = [](const std::string& command) {
    auto r = RunShell(command);
    if (r.exit_code == 124 || r.exit_code == 137) r = RunShell(command);
    return r;
  };
  const auto dom = run(ChromiumFlags(dir + "/p1") +
                       "--enable-logging=stderr --v=0 "
                       "--virtual-time-budget=5000 --dump-dom file://" +
                       html);
  ASSERT_EQ(dom.exit_code, 0) << dom.err;
  // Every figure drew: the page's own check after layout (bounding box and
  // marks of every inline SVG) writes data-figures="drawn/total".
  const std::string want = "data-figures=\"" + std::to_string(figures) + "/" +
                           std::to_string(figures) + "\"";
  EXPECT_THAT(dom.out, HasSubstr(want));
  EXPECT_THAT(dom.out, HasSubstr("data-drawn=\"yes\""));
  // No console errors or uncaught exceptions from the page.
  std::istringstream err(dom.err);
  std::string line;
  while (std::getline(err, line)) {
    if (line.find("CONSOLE") != std::string::npos ||
        line.find("Uncaught") != std::string::npos) {
      ADD_FAILURE() << "browser console: " << line;
    }
  }
  const auto shot = run(ChromiumFlags(dir + "/p2") +
                        "--window-size=1200,2400 --virtual-time-budget=5000 "
                        "--screenshot=" +
                        png + " file://" + html);
  EXPECT_EQ(shot.exit_code, 0) << shot.err;
  ASSERT_TRUE(Exists(png));
  EXPECT_GT(ReadFile(png).size(), 50000u);  // not a blank page
}

TEST(ReportCliTest, DemoSessionFullReportOpensInBrowser) {
  const std::string dir = testing::MakeTempDir("report");
  const std::string s = testing::SourceDir() + "/data/sessions/bh7_demo";
  auto d = RunKincal("diagnose model --robot " + s + "/robot.yaml --obs " + s +
                     "/observations.csv --out " + dir + "/ext.yaml --json > " +
                     dir + "/diag.json");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  // A rig and tracked points (as camcal and track write them).
  std::ofstream(dir + "/rig.yaml")
      << "kincal_rig: 1\ncameras:\n"
         "  - {name: left, width: 1280, height: 1024, fx: 1800, fy: 1800, "
         "cx: 639.5, cy: 511.5, distortion: [], cam_from_rig: {R: "
         "[1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\n"
         "  - {name: right, width: 1280, height: 1024, fx: 1810, fy: 1810, "
         "cx: 640, cy: 512, distortion: [0.01, 0, 0, 0], cam_from_rig: {R: "
         "[1,0,0,0,1,0,0,0,1], t: [-120,0,0]}}\n";
  std::ofstream(dir + "/points.csv")
      << "# written by kincal 0.1.0: kincal track ...\n"
         "frame,x,y,z,reproj_px,tags\n0,1,2,900,0.21,3\n1,,,,,0\n"
         "2,1.5,2,901,0.25,2\n3,1.7,2.1,902,0.3,3\n4,2,2,903,0.18,3\n";
  const std::string html = dir + "/report.html";
  const auto r = RunKincal("report --robot " + s + "/robot.yaml --obs " + s +
                           "/observations.csv --calibrated " + dir +
                           "/ext.yaml --diagnosis " + dir +
                           "/diag.json --rig " + dir + "/rig.yaml --session " +
                           dir + "/points.csv --out " + html + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["out"], html);
  EXPECT_TRUE(j["seconds"].is_number());
  const auto sec = Sections(j);
  for (const char* want :
       {"verdict", "diagnosis", "residuals", "structure", "workspace",
        "sensitivity", "clearance", "identifiability", "parameters", "camera",
        "tracking", "provenance"}) {
    EXPECT_THAT(sec, Contains(want));
  }
  EXPECT_EQ(sec.front(), "verdict");
  const std::string page = ReadFile(html);
  // Verdict in words: the backlash hidden in the demo data, named.
  EXPECT_THAT(page, HasSubstr("backlash in j3"));
  // Self-contained: no external resource (the SVG namespace is a name).
  const std::string no_ns =
      std::regex_replace(page, std::regex("http://www.w3.org/2000/svg"), "");
  EXPECT_THAT(no_ns, Not(HasSubstr("http://")));
  EXPECT_THAT(no_ns, Not(HasSubstr("https://")));
  EXPECT_THAT(page, Not(HasSubstr("src=")));
  EXPECT_THAT(page, HasSubstr("kincal simulate"));  // provenance of the obs
  CheckInBrowser(html, j["figures"].get<int>(),
                 std::string(KINCAL_BUILD_DIR) + "/report_demo.png");
}

TEST(ReportCliTest, SectionsAppearOnlyWithTheirInputs) {
  const std::string dir = testing::MakeTempDir("report_min");
  const auto r =
      RunKincal("report --robot " + testing::SourceDir() +
                "/data/robots/bh7.yaml --out " + dir + "/r.html --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto sec = Sections(nlohmann::json::parse(r.out));
  EXPECT_EQ(sec, (std::vector<std::string>{"verdict", "provenance"}));
}

// Gross rows in the data are named in the verdict, in words, with poses.
TEST(ReportCliTest, VerdictNamesGrossRows) {
  const std::string dir = testing::MakeTempDir("report_gross");
  const std::string robot = testing::SourceDir() + "/data/robots/bh7.yaml";
  ASSERT_EQ(RunKincal("simulate --robot " + robot + " --out " + dir +
                      "/s --poses 120 --seed 6 --json")
                .exit_code,
            0);
  // x (7th column) of data rows 11 and 51 (poses 10 and 50) moved 20 mm.
  ASSERT_EQ(RunShell("awk -F, 'BEGIN{OFS=\",\"} /^[0-9]/{n++; if(n==11||"
                     "n==51) $7=$7+20} {print}' " +
                     dir + "/s/observations.csv > " + dir + "/gross.csv")
                .exit_code,
            0);
  const auto r = RunKincal("report --robot " + robot + " --obs " + dir +
                           "/gross.csv --out " + dir + "/r.html --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string html = ReadFile(dir + "/r.html");
  EXPECT_THAT(html, HasSubstr("2 row(s) are more than 10 robust sigmas"));
  EXPECT_THAT(html, HasSubstr("left out of the fit"));
  EXPECT_THAT(html, HasSubstr("pose 10: "));
  EXPECT_THAT(html, HasSubstr("pose 50: "));
}

TEST(ReportCliTest, BadInputExitsTwoAndWritesNothing) {
  const std::string dir = testing::MakeTempDir("report_bad");
  std::ofstream(dir + "/diag.json") << "{\"verdict\": 3";
  const std::string robot = testing::SourceDir() + "/data/robots/bh7.yaml";
  auto r = RunKincal("report --robot " + robot + " --diagnosis " + dir +
                     "/diag.json --out " + dir + "/r.html");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("diag.json"));
  EXPECT_FALSE(Exists(dir + "/r.html"));
  r = RunKincal("report --out " + dir + "/r.html");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(Exists(dir + "/r.html"));
  std::ofstream(dir + "/bad.csv") << "pose,j1\n0,1\n";
  r = RunKincal("report --robot " + robot + " --obs " + dir +
                "/bad.csv --out " + dir + "/r.html");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("bad.csv"));
  EXPECT_FALSE(Exists(dir + "/r.html"));
}

// --tolerance: a pass/fail line in the page and tolerance_mm / pass in the
// JSON, exit code 0 either way.
TEST(ReportCliTest, ToleranceAddsPassFailAndKeepsExitZero) {
  const std::string dir = testing::MakeTempDir("report_tol");
  const std::string s = testing::SourceDir() + "/data/sessions/bh7_demo";
  const std::string base = "report --robot " + s + "/robot.yaml --obs " + s +
                           "/observations.csv --out " + dir + "/r.html --json";
  auto r = RunKincal(base + " --tolerance 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["tolerance_mm"], 1.0);
  EXPECT_EQ(j["pass"], true);
  EXPECT_EQ(j["decided"], true);
  ASSERT_EQ(j["heldout_ci95_mm"].size(), 2u);
  EXPECT_LT(j["heldout_ci95_mm"][0].get<double>(),
            j["heldout_rms_mm"].get<double>());
  EXPECT_THAT(ReadFile(dir + "/r.html"), HasSubstr("PASS: held-out RMS"));
  r = RunKincal(base + " --tolerance 0.01");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["pass"], false);
  EXPECT_THAT(ReadFile(dir + "/r.html"), HasSubstr("FAIL: held-out RMS"));
  // Without --tolerance the JSON has no such fields.
  r = RunKincal(base);
  EXPECT_FALSE(nlohmann::json::parse(r.out).contains("pass"));
}

// 16 poses: no percentages of explained variance, "too few poses" instead.
TEST(ReportCliTest, FewPosesSayTooFewInsteadOfPercentages) {
  const std::string dir = testing::MakeTempDir("report_few");
  const std::string robot = testing::SourceDir() + "/data/robots/bh7.yaml";
  ASSERT_EQ(RunKincal("simulate --robot " + robot + " --out " + dir +
                      "/s --poses 16 --seed 3 --json")
                .exit_code,
            0);
  const auto r = RunKincal("report --robot " + robot + " --obs " + dir +
                           "/s/observations.csv --out " + dir + "/r.html");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string html = ReadFile(dir + "/r.html");
  EXPECT_THAT(html, HasSubstr("too few poses (16)"));
  EXPECT_THAT(html, Not(HasSubstr("grid explains")));
  EXPECT_THAT(html, HasSubstr("a rough figure"));  // 3 held-out poses
  // A tolerance is not decided on 3 held-out poses: pass is null.
  const auto t = RunKincal("report --robot " + robot + " --obs " + dir +
                           "/s/observations.csv --out " + dir +
                           "/r.html --tolerance 0.5 --json");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const auto j = nlohmann::json::parse(t.out);
  EXPECT_TRUE(j["pass"].is_null());
  EXPECT_EQ(j["decided"], false);
  EXPECT_THAT(ReadFile(dir + "/r.html"), HasSubstr("NOT DECIDED"));
}

// --bundle: the bundle's own figures, no calibration run by the report.
TEST(ReportCliTest, BundleResultIsShownNotRecalibrated) {
  const std::string dir = testing::MakeTempDir("report_bundle");
  const std::string s = testing::SourceDir() + "/data/sessions/bh7_demo";
  std::ofstream(dir + "/bundle.json")
      << R"({"command": "kincal bundle ...", "reproj_rms_px": 0.0504,
             "heldout_reproj_rms_px": 0.0295, "sigma0_px": 0.036,
             "heldout_tip_rms_mm": 0.449, "heldout_tips": 6,
             "heldout_frames": 6, "identifiable": ["j2.a"],
             "unidentifiable": ["j1.d"],
             "params": [{"name": "j2.a", "value": 200.161, "sigma": 0.0086}]})";
  const auto r = RunKincal("report --robot " + s + "/robot.yaml --obs " + s +
                           "/observations.csv --bundle " + dir +
                           "/bundle.json --out " + dir + "/r.html --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto sec = Sections(nlohmann::json::parse(r.out));
  EXPECT_THAT(sec, Contains("parameters"));
  const std::string html = ReadFile(dir + "/r.html");
  EXPECT_THAT(html, HasSubstr("held-out tip error 0.449 mm"));
  EXPECT_THAT(html, HasSubstr("sigma0 0.036 px"));
  EXPECT_THAT(html, Not(HasSubstr("Geometric calibration (run here")));
  EXPECT_THAT(html, HasSubstr("bundle result"));  // provenance row
}

// The camera section from a real camera calibration (OpenCV's stereo
// chessboard images): camcal's JSON saved beside the rig is found, and the
// per-view and over-the-image figures draw (screenshot in the build folder).
TEST(ReportCliTest, CameraSectionFromRealCamcal) {
  KINCAL_REQUIRE_SHARED_DATA("opencv-stereo-left-right");
  const std::string dir = testing::MakeTempDir("report_camcal");
  const std::string stereo =
      testing::SharedDataDir() + "/opencv-stereo-left-right";
  const auto c =
      RunKincal("camcal --left '" + stereo + "/left*.jpg' --right '" + stereo +
                "/right*.jpg' --target chessboard:9x6:1 " + "--out " + dir +
                "/rig.yaml --json > " + dir + "/rig.json");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const std::string html = dir + "/report.html";
  const auto r =
      RunKincal("report --rig " + dir + "/rig.yaml --out " + html + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_THAT(Sections(j), Contains("camera"));
  // Per view + per camera the residual map and the uncertainty map.
  EXPECT_EQ(j["figures"], 5);
  const std::string page = ReadFile(html);
  EXPECT_THAT(page, HasSubstr("left: residual over the image"));
  EXPECT_THAT(page, HasSubstr("right: projection uncertainty"));
  EXPECT_THAT(page, HasSubstr("right: residual over the image"));
  EXPECT_THAT(page, HasSubstr("sigma fx"));
  CheckInBrowser(html, 5, std::string(KINCAL_BUILD_DIR) + "/report_camera.png");
}

// The UR10 series C report (real laser-tracker data) shows the residual
// structure over shoulder_pan x shoulder_lift that the diagnosis left
// unexplained.
TEST(ReportCliTest, Ur10SeriesCShowsPanLiftStructure) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy/Series_C");
  const std::string dir = testing::MakeTempDir("report_ur10");
  auto r = RunKincal("import ipa-ur10 --in " + testing::SharedDataDir() +
                     "/ipa-robot-accuracy/Series_C/measurements_random_poses"
                     ".csv --robot " +
                     testing::SourceDir() + "/data/robots/ur10.yaml --out " +
                     dir + "/obs.csv --every 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunKincal("report --robot " + testing::SourceDir() +
                "/data/robots/ur10.yaml --obs " + dir + "/obs.csv --out " +
                dir + "/ur10.html --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(Sections(nlohmann::json::parse(r.out)), Contains("structure"));
  EXPECT_THAT(ReadFile(dir + "/ur10.html"),
              HasSubstr("Residual structure over shoulder_pan_joint x "
                        "shoulder_lift_joint"));
  // The import keeps the tracker's temperature and time: both plots drawn.
  EXPECT_THAT(ReadFile(dir + "/obs.csv"), HasSubstr("temp_c"));
  EXPECT_THAT(ReadFile(dir + "/ur10.html"), HasSubstr("against temperature"));
  EXPECT_THAT(ReadFile(dir + "/ur10.html"), HasSubstr("against time"));
}

}  // namespace
}  // namespace kincal
