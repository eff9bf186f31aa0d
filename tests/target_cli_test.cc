// `kincal target` end to end on a rendered recorded session of the tool on
// the robot (the spec's contract: flags, JSON fields, exit codes, nothing
// written on bad input): the measured tag layout against the truth of the
// simulation, compared as relative poses (the measured tool frame is the
// reference tag's), and `track` with the measured target against `track`
// with the true one.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "camcal/rig.h"
#include "data/rigid3.h"
#include "synth/recorded_session.h"
#include "synth/render.h"
#include "tests/target_monte_carlo.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"
#include "tests/testing/tilt.h"
#include "vision/target.h"

namespace kincal::testing {
namespace {

std::string Bh7() { return SourceDir() + "/data/robots/bh7.yaml"; }

// A rendered robot session at the renderer's full size (1280 x 1024).
std::string Simulate(const std::string& dir, int poses, int seed) {
  const RunResult r = RunKincal(
      "simulate --robot " + Bh7() + " --out " + dir + " --poses " +
      std::to_string(poses) + " --noise 0 --seed " + std::to_string(seed) +
      " --render --render-noise 1.5 --render-blur 0.5");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return dir;
}

std::string TargetArgs(const std::string& s, double size) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", size);
  return "target --rig " + s + "/rig.yaml --session " + s +
         "/session --family tag36h11 --size " + buf + " --quiet ";
}

// Columns x, y, z (from column `first`) of a CSV by row; NaN where empty.
// points.csv has the tip at columns 1-3 (and `tags` at 5: rows with fewer
// than two tags, which track's quality gate leaves out, read as NaN), the
// session's truth.csv at 13-15.
std::vector<Eigen::Vector3d> ReadTips(const std::string& path, int first) {
  std::ifstream f(path);
  std::string line;
  std::vector<Eigen::Vector3d> tips;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'f') continue;
    std::stringstream ss(line);
    std::string cell;
    std::vector<std::string> cells;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    const bool one_tag = first == 1 && cells.size() > 5 && cells[5] < "2";
    if (static_cast<int>(cells.size()) < first + 3 || cells[first].empty() ||
        one_tag) {
      tips.push_back(Eigen::Vector3d::Constant(NAN));
    } else {
      tips.emplace_back(std::stod(cells[first]), std::stod(cells[first + 1]),
                        std::stod(cells[first + 2]));
    }
  }
  return tips;
}

// Tip RMS against the truth with the measured and with the true target, over
// the frames both found.
struct TipErrors {
  double measured_mm, true_mm;
  int frames;
};
TipErrors TipRms(const std::vector<Eigen::Vector3d>& measured,
                 const std::vector<Eigen::Vector3d>& with_true,
                 const std::vector<Eigen::Vector3d>& truth) {
  double sum_measured = 0, sum_true = 0;
  int n = 0;
  for (size_t f = 0; f < truth.size(); ++f) {
    if (!measured[f].allFinite() || !with_true[f].allFinite()) continue;
    sum_measured += (measured[f] - truth[f]).squaredNorm();
    sum_true += (with_true[f] - truth[f]).squaredNorm();
    ++n;
  }
  return {std::sqrt(sum_measured / std::max(n, 1)),
          std::sqrt(sum_true / std::max(n, 1)), n};
}

TEST(TargetCli, MeasuresTheRenderedToolsLayout) {
  const std::string dir = MakeTempDir("target");
  const std::string s = Simulate(dir + "/s", 60, 5);
  const Target truth = ReadTargetYaml(s + "/target.yaml");
  const double size = truth.tags[0].size_mm;
  RunResult r =
      RunKincal(TargetArgs(s, size) + "--out " + dir + "/t.yaml --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* field :
       {"views_used", "tags", "tip_in_tool", "tip_sigma_mm", "seconds"}) {
    EXPECT_TRUE(j.contains(field)) << field;
  }
  EXPECT_FALSE(j.contains("pivot_rms_mm"));
  EXPECT_TRUE(j["tip_in_tool"].is_null());
  // The robot's poses show two or more tags in about a third of the frames:
  // the layout is measured, with a warning naming the count and what to
  // record instead.
  EXPECT_GE(j["views_used"].get<int>(), 15);
  ASSERT_TRUE(j.contains("warnings")) << r.out;
  EXPECT_EQ(j["warnings"][0]["code"], "few_layout_views");
  EXPECT_NE(j["warnings"][0]["message"].get<std::string>().find(
                "pairs of neighbouring tags"),
            std::string::npos);
  EXPECT_NE(r.err.find("few_layout_views"), std::string::npos) << r.err;
  ASSERT_EQ(j["tags"].size(), truth.tags.size());
  for (const auto& t : j["tags"]) {
    EXPECT_TRUE(t.contains("id") && t.contains("sigma_t_mm") &&
                t.contains("sigma_r_deg"));
  }

  Target measured = ReadTargetYaml(dir + "/t.yaml");
  EXPECT_FALSE(measured.has_tip);
  EXPECT_NE(measured.made_by.find("target --rig"), std::string::npos);
  const int ref = j["reference_tag"].get<int>();
  const TargetTag* true_ref = truth.FindTag(ref);
  ASSERT_NE(true_ref, nullptr);
  double max_t = 0, max_r = 0, z2 = 0;
  int count = 0;
  for (const TargetTag& tag : measured.tags) {
    const TargetTag* want = truth.FindTag(tag.id);
    ASSERT_NE(want, nullptr) << tag.id;
    EXPECT_TRUE(tag.has_sigma);
    const Rigid3 ref_from_tag =
        true_ref->tool_from_tag.Inverse() * want->tool_from_tag;
    const Eigen::Vector3d dt = tag.tool_from_tag.t - ref_from_tag.t;
    const Eigen::Vector3d dr =
        RotationVectorFromMatrix(tag.tool_from_tag.R *
                                 ref_from_tag.R.transpose()) *
        180 / M_PI;
    max_t = std::max(max_t, dt.norm());
    max_r = std::max(max_r, dr.norm());
    if (tag.id == ref) continue;
    for (int k = 0; k < 3; ++k) {
      z2 += std::pow(dt(k) / tag.sigma_t_mm(k), 2) +
            std::pow(dr(k) / tag.sigma_r_deg(k), 2);
      count += 2;
    }
  }
  std::printf(
      "target: %d views, max tag error %.4f mm %.4f deg, RMS error/sigma "
      "%.2f, %.1f s\n",
      j["views_used"].get<int>(), max_t, max_r, std::sqrt(z2 / count),
      j["seconds"].get<double>());
  // 19 views of rendered images: measured 0.023 mm / 0.044 deg, RMS
  // error/sigma 1.46 (docs/VISION.md).
  EXPECT_LT(max_t, 0.05);
  EXPECT_LT(max_r, 0.08);
  EXPECT_LT(std::sqrt(z2 / count), 2.0);

  // track with the measured layout and the true tip carried into its frame,
  // against track with the true target.
  measured.has_tip = true;
  measured.tip_in_tool = true_ref->tool_from_tag.Inverse() * truth.tip_in_tool;
  WriteTargetYaml(dir + "/m.yaml", measured);
  for (const char* which : {"m", "true"}) {
    const std::string target =
        std::string(which) == "m" ? dir + "/m.yaml" : s + "/target.yaml";
    r = RunKincal("track --rig " + s + "/rig.yaml --target " + target +
                  " --session " + s + "/session --quiet --out " + dir + "/" +
                  which + ".csv");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  // The criterion: the tip RMS against the truth with the measured
  // target within sqrt((1.1 r)^2 + 0.1^2), r the RMS with the true one
  // (measured 0.157 mm against 0.146 mm).
  const auto measured_tips = ReadTips(dir + "/m.csv", 1);
  const auto true_tips = ReadTips(dir + "/true.csv", 1);
  const auto truth_tips = ReadTips(s + "/session/truth.csv", 13);
  ASSERT_EQ(measured_tips.size(), truth_tips.size());
  ASSERT_EQ(true_tips.size(), truth_tips.size());
  const auto [r_measured, r_true, n] =
      TipRms(measured_tips, true_tips, truth_tips);
  ASSERT_GT(n, 10);
  std::printf(
      "track: tip RMS against the truth %.4f mm with the measured target, "
      "%.4f mm with the true one (%d frames)\n",
      r_measured, r_true, n);
  EXPECT_LT(r_measured, std::hypot(1.1 * r_true, 0.1));
  EXPECT_LT(r_true, 0.3);
}

// Monte Carlo over random holders (tests/target_monte_carlo.h, 2 of the 8
// seeds of bench/target_bench --plain): tags within 0.05 mm / 0.05 deg,
// the tip within 0.1 mm, and error / sigma pooled over both seeds within
// loose bounds (12 to 18 numbers each; the bench pools 51).
TEST(TargetCli, RandomHoldersMonteCarlo) {
  std::vector<double> z_t, z_r, z_tip;
  for (int seed : {1, 2}) {
    const McTrial t =
        RunTargetTrial(seed, LayoutCovariance::kTagObservations, true);
    std::printf(
        "seed %d: %d tags, max tag error %.4f mm %.4f deg, tip %.4f mm "
        "(sigma %.4f: pivot %.4f, layout %.4f)\n",
        seed, t.tags, t.max_t_mm, t.max_r_deg, t.tip_mm, t.tip_sigma_mm,
        t.tip_pivot_sigma_mm, t.tip_layout_sigma_mm);
    EXPECT_LT(t.max_t_mm, 0.05) << seed;
    EXPECT_LT(t.max_r_deg, 0.05) << seed;
    EXPECT_LT(t.tip_mm, 0.1) << seed;
    EXPECT_GT(t.tip_layout_sigma_mm, 0.0) << seed;
    z_t.insert(z_t.end(), t.z_t.begin(), t.z_t.end());
    z_r.insert(z_r.end(), t.z_r.begin(), t.z_r.end());
    z_tip.insert(z_tip.end(), t.z_tip.begin(), t.z_tip.end());
  }
  std::printf("RMS error/sigma: t %.2f, r %.2f, tip %.2f\n", RmsOf(z_t),
              RmsOf(z_r), RmsOf(z_tip));
  // Measured 0.52, 0.99, 0.62 here; 1.04, 1.01, 0.87 over 16 seeds
  // (target_bench --plain --seeds 16). The tip pools 6 numbers: the RMS of
  // 6 standard normals is below 0.52 in 5 % of draws and below 0.35 in
  // 0.6 %, so its lower bound is 0.35. The tags pool 21, but the tags of
  // one holder share their errors (one pivot, one layout): per seed the
  // translations' RMS error/sigma ranges 0.12-1.75 over those 16 seeds, so
  // two seeds are nearer two numbers than 21, and its bound is 0.4.
  EXPECT_GT(RmsOf(z_t), 0.4);
  EXPECT_GT(RmsOf(z_r), 0.6);
  EXPECT_GT(RmsOf(z_tip), 0.35);
  for (double z : {RmsOf(z_t), RmsOf(z_r), RmsOf(z_tip)}) EXPECT_LT(z, 2.0);
}

// The blurriest holder of target_bench's widened effects (seed 5: 4 tags,
// blur 0.89 px, noise 2.2): its tip was 0.228 mm off with the unweighted
// pivot fit that kept a pose 0.4 mm off the pivot (one bad tag observation
// turning it 0.18 deg); measured 0.090 mm now. The issue asks 0.1 mm.
TEST(TargetCli, BlurryHolderTipWithinATenth) {
  const McTrial t = RunTargetTrial(5, LayoutCovariance::kTagObservations);
  std::printf(
      "seed 5 (blur %.2f px): max tag error %.4f mm %.4f deg, tip %.4f mm "
      "(sigma %.4f), %d pivot views\n",
      t.effects.blur_sigma_px, t.max_t_mm, t.max_r_deg, t.tip_mm,
      t.tip_sigma_mm, t.pivot_views);
  EXPECT_GT(t.effects.blur_sigma_px, 0.85);
  EXPECT_LT(t.max_t_mm, 0.05);
  EXPECT_LT(t.max_r_deg, 0.05);
  EXPECT_LT(t.tip_mm, 0.1);
  // Its tip error comes from the corners' bias fixed to the tags, which
  // every view shares (docs/VISION.md, "Errors every view shares"): the
  // shared term sees it (5.5 um per axis) and the tip's sigma holds the
  // error within 2.5 sigma (0.090 / 0.044 mm; without it 0.090 / 0.023).
  EXPECT_GT(t.corner_offset_sigma_mm, 0.002);
  EXPECT_LT(t.tip_mm, 2.5 * t.tip_sigma_mm);
}

// A hand-held session of the example tool (40 views) and a pivot session
// (the tip fixed, tilted +-20 deg about two axes): the tip in the measured
// tool frame against the truth carried into that frame.
TEST(TargetCli, PivotSessionGivesTheTip) {
  const std::string dir = MakeTempDir("target_pivot");
  const Rig rig = ExampleStereoRig(640, 512);
  const Target truth = ExampleTarget();
  WriteRigYaml(dir + "/rig.yaml", rig);
  RenderOptions o;
  o.blur_sigma_px = 0.5;
  o.noise_sigma = 1.5;
  RecordedSessionInput views, pivot;
  for (int i = 0; i < 40; ++i) {
    views.rig_from_tool.push_back(
        testing::TiltedAbout(ExampleToolPose(i), 20 * std::sin(0.9 * i),
                             25 * std::cos(0.6 * i), Eigen::Vector3d::Zero()));
  }
  const Rigid3 mid = ExampleToolPose(0);
  for (int i = 0; i < 16; ++i) {
    const double a = 2 * M_PI * i / 16;
    pivot.rig_from_tool.push_back(testing::TiltedAbout(
        mid, 20 * std::sin(a), 20 * std::cos(a), truth.tip_in_tool));
  }
  RenderRecordedSession(rig, truth, views, o, 11, dir + "/views");
  RenderRecordedSession(rig, truth, pivot, o, 12, dir + "/pivot");
  const RunResult r =
      RunKincal("target --rig " + dir + "/rig.yaml --session " + dir +
                "/views --family tag36h11 --size 25 --pivot " + dir +
                "/pivot --out " + dir + "/t.yaml --json --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("pivot_rms_mm"));
  ASSERT_TRUE(j["pivot_frames_rejected"].is_array());
  EXPECT_EQ(j["pivot_views"].get<int>() +
                static_cast<int>(j["pivot_frames_rejected"].size()),
            16);
  const Target measured = ReadTargetYaml(dir + "/t.yaml");
  ASSERT_TRUE(measured.has_tip && measured.has_tip_sigma);
  const TargetTag* true_ref = truth.FindTag(j["reference_tag"].get<int>());
  ASSERT_NE(true_ref, nullptr);
  double max_t = 0, max_r = 0, z2 = 0;
  int count = 0;
  for (const TargetTag& tag : measured.tags) {
    const TargetTag* true_tag = truth.FindTag(tag.id);
    ASSERT_NE(true_tag, nullptr);
    const Rigid3 ref_from_tag =
        true_ref->tool_from_tag.Inverse() * true_tag->tool_from_tag;
    if (tag.id != true_ref->id) {
      const Eigen::Vector3d dt = tag.tool_from_tag.t - ref_from_tag.t;
      const Eigen::Vector3d dr =
          RotationVectorFromMatrix(tag.tool_from_tag.R *
                                   ref_from_tag.R.transpose()) *
          180 / M_PI;
      for (int k = 0; k < 3; ++k) {
        z2 += std::pow(dt(k) / tag.sigma_t_mm(k), 2) +
              std::pow(dr(k) / tag.sigma_r_deg(k), 2);
        count += 2;
      }
    }
    max_t = std::max(max_t, (tag.tool_from_tag.t - ref_from_tag.t).norm());
    max_r = std::max(max_r, RotationVectorFromMatrix(tag.tool_from_tag.R *
                                                     ref_from_tag.R.transpose())
                                    .norm() *
                                180 / M_PI);
  }
  std::printf(
      "tool alone: %d views, max tag error %.4f mm %.4f deg, RMS "
      "error/sigma %.2f\n",
      j["views_used"].get<int>(), max_t, max_r, std::sqrt(z2 / count));
  EXPECT_LT(max_t, 0.05);
  EXPECT_LT(max_r, 0.05);
  // One seed, 18 numbers: measured 1.05; loose bounds.
  EXPECT_GT(std::sqrt(z2 / count), 0.5);
  EXPECT_LT(std::sqrt(z2 / count), 2.0);
  const Eigen::Vector3d want =
      true_ref->tool_from_tag.Inverse() * truth.tip_in_tool;
  const Eigen::Vector3d error = measured.tip_in_tool - want;
  std::printf(
      "pivot: tip error %.4f mm (sigma %.4f %.4f %.4f mm), pivot RMS %.4f mm, "
      "tilt %.1f deg\n",
      error.norm(), measured.tip_sigma_mm.x(), measured.tip_sigma_mm.y(),
      measured.tip_sigma_mm.z(), j["pivot_rms_mm"].get<double>(),
      j["pivot_tilt_deg"].get<double>());
  EXPECT_LT(error.norm(), 0.1);
  EXPECT_EQ(j["tip_sigma_mm"].size(), 3u);
  EXPECT_EQ(j["tip_shared_sigma_mm"].size(), 3u);
  EXPECT_GE(j["corner_offset_sigma_mm"].get<double>(), 0.0);

  // The criterion on the tool-alone session: track with the measured
  // target (layout and pivot tip) against track with the true target, both
  // against the rendered truth: r_measured <= sqrt((1.1 r)^2 + 0.1^2).
  WriteTargetYaml(dir + "/true.yaml", truth);
  for (const char* which : {"t", "true"}) {
    const RunResult tr =
        RunKincal("track --rig " + dir + "/rig.yaml --target " + dir + "/" +
                  which + ".yaml --session " + dir + "/views --quiet --out " +
                  dir + "/" + which + ".csv");
    ASSERT_EQ(tr.exit_code, 0) << tr.err;
  }
  const auto measured_tips = ReadTips(dir + "/t.csv", 1);
  const auto true_tips = ReadTips(dir + "/true.csv", 1);
  const auto truth_tips = ReadTips(dir + "/views/truth.csv", 13);
  ASSERT_EQ(measured_tips.size(), truth_tips.size());
  const auto [r_measured, r_true, n] =
      TipRms(measured_tips, true_tips, truth_tips);
  ASSERT_GT(n, 30);
  std::printf(
      "tool alone, track: tip RMS %.4f mm with the measured target, %.4f mm "
      "with the true one (%d frames)\n",
      r_measured, r_true, n);
  EXPECT_LT(r_measured, std::hypot(1.1 * r_true, 0.1));

  // A pivot session tilted +-2 deg only: refused with what to record.
  RecordedSessionInput flat;
  for (int i = 0; i < 16; ++i) {
    flat.rig_from_tool.push_back(testing::TiltedAbout(
        mid, 2 * std::sin(0.4 * i), 2 * std::cos(0.4 * i), truth.tip_in_tool));
  }
  RenderRecordedSession(rig, truth, flat, o, 13, dir + "/flat");
  const RunResult refused =
      RunKincal("target --rig " + dir + "/rig.yaml --session " + dir +
                "/views --family tag36h11 --size 25 --pivot " + dir +
                "/flat --out " + dir + "/t2.yaml --quiet");
  EXPECT_EQ(refused.exit_code, 2) << refused.out;
  EXPECT_NE(refused.err.find("tilt the tool more"), std::string::npos)
      << refused.err;
  EXPECT_FALSE(Exists(dir + "/t2.yaml"));
}

TEST(TargetCli, RefusesTooFewViewsAndWritesNothing) {
  const std::string dir = MakeTempDir("target_few");
  const std::string s = Simulate(dir + "/s", 6, 2);
  RunResult r =
      RunKincal(TargetArgs(s, 25) + "--out " + dir + "/t.yaml --json");
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("record the tool from more directions"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(Exists(dir + "/t.yaml"));
  r = RunKincal(TargetArgs(s, 0) + "--out " + dir + "/t.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
  r = RunKincal(TargetArgs(s, 25) + "--pivot " + dir + "/nowhere --out " + dir +
                "/t.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(Exists(dir + "/t.yaml"));
}

}  // namespace
}  // namespace kincal::testing
