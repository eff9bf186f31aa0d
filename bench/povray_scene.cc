// A second renderer for the tracker and the bundle: POV-Ray (a ray tracer
// we did not write) renders a session that `kincal simulate --render` laid
// out, so the tests see images whose antialiasing, texture sampling, shading
// and shadows share nothing with synth/render.cc. Three steps:
//
//   povray_scene scene --sim S --out P [--light-deg A] [--margin CELLS]
//       [--light-distance D]
//       writes P/rig.yaml (S's rig without lens distortion: POV-Ray's camera
//       is a pinhole), P/target.yaml, P/pov/<camera>_<frame>.pov (one scene
//       per view: the tags as matte paper on grey anodised plates, the
//       needle, a checked table behind, an area light from the side and a
//       weak light at the rig) and P/session (frames.csv, session.yaml, and
//       truth.csv / corners.csv for the pinhole rig)
//   povray +IP/pov/left_000000.pov +OP/raw/left/000000.png ... (the script)
//   povray_scene finish --out P [--noise SIGMA] [--shot S] [--blur B]
//       [--seed N]
//       P/raw/<camera>/*.png -> 8-bit gray with read noise SIGMA (levels)
//       and shot noise (variance S x level), after a Gaussian blur of B px
//       (a lens; 0 = none, POV-Ray's pinhole is sharp) into
//       P/session/<camera>/
//   povray_scene score --out P --points points.csv
//       the tracked tips against truth.csv: all written tips and those that
//       pass track's gate (>= 2 tags, <= 0.5 px): count, RMS, max, mm
//   povray_scene detect --image IMG [--decimate D]
//       the tags kincal's detector finds in one image
//
// bench/povray_session.sh runs the whole chain (track, bundle, evaluate);
// synth/povray_scene.h writes the scenes.

#include "synth/povray_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/rigid3.h"
#include "synth/render.h"
#include "vision/apriltag_detector.h"
#include "vision/target.h"

namespace kincal {
namespace {

namespace fs = std::filesystem;

struct TruthRow {
  int frame = 0;
  Rigid3 rig_from_tool;
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
};

// The data rows of a kincal CSV (data/csv.h; header skipped), each as its
// fields separated by spaces for a stream.
std::vector<std::string> CsvRows(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  const std::vector<CsvLine> lines = TokenizeCsv(text.str(), path);
  std::vector<std::string> rows;
  for (size_t i = 1; i < lines.size(); ++i) {
    std::string row;
    for (const CsvField& f : lines[i].fields) row += f.text + " ";
    rows.push_back(row);
  }
  return rows;
}

std::vector<TruthRow> ReadTruth(const std::string& path) {
  std::vector<TruthRow> out;
  for (const std::string& row : CsvRows(path)) {
    std::istringstream is(row);
    TruthRow t;
    is >> t.frame;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) is >> t.rig_from_tool.R(r, c);
    is >> t.rig_from_tool.t.x() >> t.rig_from_tool.t.y() >>
        t.rig_from_tool.t.z() >> t.tip.x() >> t.tip.y() >> t.tip.z();
    if (!is) throw InputError(path + ": bad row '" + row + "'");
    out.push_back(t);
  }
  return out;
}

int Scene(const std::string& sim, const std::string& out,
          const PovSceneOptions& options) {
  Rig rig = ReadRigYaml(sim + "/rig.yaml");
  const Target target = ReadTargetYaml(sim + "/target.yaml");
  const std::vector<TruthRow> truth = ReadTruth(sim + "/session/truth.csv");
  for (Camera& c : rig.cameras)
    c.intrinsics.distortion.assign(c.intrinsics.distortion.size(), 0.0);
  fs::create_directories(out + "/pov");
  fs::create_directories(out + "/session");
  WriteRigYaml(out + "/rig.yaml", rig);
  fs::copy_file(sim + "/target.yaml", out + "/target.yaml",
                fs::copy_options::overwrite_existing);
  for (const char* f : {"frames.csv", "session.yaml"})
    fs::copy_file(sim + "/session/" + f, out + "/session/" + f,
                  fs::copy_options::overwrite_existing);
  WriteTagImages(target, out + "/pov");
  double depth = 0;
  for (const TruthRow& t : truth)
    depth = std::max(depth, t.rig_from_tool.t.z());
  TruthTables tables("# written by povray_scene from " + sim, 0);
  std::vector<std::string> labels;  // corners.csv: camera index in the rig
  for (size_t c = 0; c < rig.cameras.size(); ++c)
    labels.push_back(std::to_string(c));
  for (const TruthRow& t : truth) {
    StereoFrameTruth frame;
    frame.rig_from_tool = t.rig_from_tool;
    frame.tip_in_rig = t.tip;
    for (const Camera& cam : rig.cameras) {
      char name[64];
      std::snprintf(name, sizeof name, "%s_%06d.pov",
                    cam.intrinsics.name.c_str(), t.frame);
      WriteFileAtomic(out + "/pov/" + name,
                      PovViewScene(cam.intrinsics, cam.cam_from_rig, target,
                                   t.rig_from_tool, depth, options));
      ViewTruth view;
      view.tags = ProjectTargetCorners(cam, target, t.rig_from_tool);
      frame.views.push_back(view);
    }
    tables.Add(static_cast<size_t>(t.frame), frame, labels);
  }
  WriteFileAtomic(out + "/session/truth.csv", tables.TruthCsv());
  WriteFileAtomic(out + "/session/corners.csv", tables.CornersCsv());
  std::printf("%zu frames x %zu cameras of scenes in %s/pov\n", truth.size(),
              rig.cameras.size(), out.c_str());
  return 0;
}

// The renders as a sensor gives them (SensorImage).
int Finish(const std::string& out, double noise, double shot, double blur,
           uint64_t seed) {
  const Rig rig = ReadRigYaml(out + "/rig.yaml");
  std::mt19937_64 rng(seed);
  int written = 0;
  for (const std::string& name : rig.CameraNames()) {
    fs::create_directories(out + "/session/" + name);
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(out + "/raw/" + name))
      if (e.path().extension() == ".png") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      cv::Mat rendered = cv::imread(f.string(), cv::IMREAD_COLOR);
      if (rendered.empty()) throw InputError(f.string() + ": cannot read");
      // The lens's blur, which POV-Ray's pinhole does not have.
      if (blur > 0) cv::GaussianBlur(rendered, rendered, cv::Size(), blur);
      cv::imwrite(out + "/session/" + name + "/" + f.filename().string(),
                  SensorImage(rendered, noise, shot, &rng));
      ++written;
    }
  }
  std::printf("%d images finished (read noise %.2f, shot %.3f)\n", written,
              noise, shot);
  return 0;
}

int Score(const std::string& out, const std::string& points) {
  std::map<int, Eigen::Vector3d> truth;
  for (const TruthRow& t : ReadTruth(out + "/session/truth.csv"))
    truth[t.frame] = t.tip;
  int frames = 0;
  std::vector<double> all, gated;
  for (const std::string& row : CsvRows(points)) {
    std::istringstream is(row);
    int frame, tags;
    Eigen::Vector3d p;
    double reproj;
    ++frames;
    if (!(is >> frame >> p.x() >> p.y() >> p.z() >> reproj >> tags))
      continue;  // no tip
    const double e = (p - truth.at(frame)).norm();
    all.push_back(e);
    if (tags >= 2 && reproj <= 0.5) gated.push_back(e);
  }
  auto print = [](const char* what, const std::vector<double>& e) {
    double sq = 0, worst = 0;
    for (double x : e) {
      sq += x * x;
      worst = std::max(worst, x);
    }
    std::printf(" %s %zu RMS %.4f max %.4f mm;", what, e.size(),
                e.empty() ? 0.0 : std::sqrt(sq / e.size()), worst);
  };
  std::printf("%d frames:", frames);
  print("tips", all);
  print("gated", gated);
  std::printf("\n");
  return 0;
}

// Detections in one image (libapriltag + kincal's refinement), for a look
// at a single view.
int Detect(const std::string& image, int decimate) {
  const cv::Mat gray = cv::imread(image, cv::IMREAD_GRAYSCALE);
  if (gray.empty()) throw InputError(image + ": cannot read");
  AprilTagOptions options;
  options.quad_decimate = decimate;
  AprilTagDetector detector(options);
  for (const TagDetection& d : detector.Detect(gray)) {
    std::printf("id %d margin %.1f hamming %d corners", d.id, d.decision_margin,
                d.hamming);
    for (const Eigen::Vector2d& c : d.corners)
      std::printf(" (%.3f, %.3f)", c.x(), c.y());
    std::printf("\n");
  }
  return 0;
}

std::string Arg(int argc, char** argv, const std::string& name,
                const std::string& fallback) {
  for (int i = 2; i + 1 < argc; ++i)
    if (argv[i] == name) return argv[i + 1];
  return fallback;
}

}  // namespace
}  // namespace kincal

int main(int argc, char** argv) {
  using kincal::Arg;
  const std::string mode = argc > 1 ? argv[1] : "";
  const std::string out = Arg(argc, argv, "--out", "");
  try {
    if (mode == "scene" && !out.empty()) {
      kincal::PovSceneOptions options;
      options.light_deg = std::stod(Arg(argc, argv, "--light-deg", "35"));
      options.margin_cells = std::stod(Arg(argc, argv, "--margin", "0"));
      options.light_distance =
          std::stod(Arg(argc, argv, "--light-distance", "1.1"));
      return kincal::Scene(Arg(argc, argv, "--sim", ""), out, options);
    }
    if (mode == "finish" && !out.empty()) {
      return kincal::Finish(out, std::stod(Arg(argc, argv, "--noise", "1.0")),
                            std::stod(Arg(argc, argv, "--shot", "0.02")),
                            std::stod(Arg(argc, argv, "--blur", "0")),
                            std::stoull(Arg(argc, argv, "--seed", "1")));
    }
    if (mode == "detect")
      return kincal::Detect(Arg(argc, argv, "--image", ""),
                            std::stoi(Arg(argc, argv, "--decimate", "2")));
    if (mode == "score" && !out.empty())
      return kincal::Score(out, Arg(argc, argv, "--points", ""));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "povray_scene: %s\n", e.what());
    return 2;
  }
  std::fprintf(stderr,
               "usage: povray_scene scene --sim S --out P [--light-deg A] "
               "[--margin CELLS] [--light-distance D]\n"
               "       povray_scene finish --out P [--noise L] [--shot S] "
               "[--blur B] [--seed N]\n"
               "       povray_scene score --out P --points points.csv\n"
               "       povray_scene detect --image IMG [--decimate D]\n");
  return 2;
}
