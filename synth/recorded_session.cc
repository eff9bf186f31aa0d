#include "synth/recorded_session.h"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/session.h"
#include "data/yaml_util.h"

namespace kincal {

int RenderRecordedSession(const Rig& rig, const Target& target,
                          const RecordedSessionInput& input,
                          const RenderOptions& options, uint64_t seed,
                          const std::string& dir) {
  options.Check();
  const size_t n = input.rig_from_tool.size();
  const std::vector<std::string> cameras = rig.CameraNames();
  for (const std::string& name : cameras) {
    CheckSessionCameraName(name, "render: the rig");
  }
  if (!input.joints.empty() && input.joints.size() != n) {
    throw InputError("render: joint readings for " +
                     std::to_string(input.joints.size()) + " frames, poses " +
                     std::to_string(n));
  }
  std::error_code ec;
  if (std::filesystem::exists(dir + "/frames.csv", ec)) {
    throw InputError(dir + ": already holds a session (frames.csv)");
  }
  for (const std::string& name : cameras) {
    std::filesystem::create_directories(dir + "/" + name, ec);
    if (ec) {
      throw InputError(dir + "/" + name +
                       ": cannot create the folder: " + ec.message());
    }
  }
  StereoRenderer renderer(rig, target, options);
  std::mt19937_64 rng(seed);
  const std::string header =
      "# written by " + ToolVersion() + ": " + CommandLine() + "\n";
  std::ostringstream frames;
  TruthTables tables(header, seed);
  frames << header << SessionFramesHeader(cameras, input.joint_names) << "\n";
  const std::vector<int> png_params = {cv::IMWRITE_PNG_COMPRESSION, 1};
  for (size_t f = 0; f < n; ++f) {
    const StereoFrameTruth frame =
        renderer.Render(input.rig_from_tool[f], &rng);
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", f);
    for (size_t c = 0; c < cameras.size(); ++c) {
      std::vector<uchar> png;
      cv::imencode(".png", frame.views[c].image, png, png_params);
      WriteFileAtomic(dir + "/" + cameras[c] + "/" + name,
                      std::string(png.begin(), png.end()));
    }
    const double t = input.t_s.size() == n ? input.t_s[f] : 0.1 * f;
    frames << f;
    for (size_t c = 0; c < cameras.size(); ++c)
      frames << "," << FormatDouble(t);
    for (size_t c = 0; c < cameras.size(); ++c) frames << "," << f;
    const bool has = !input.joints.empty() && !input.joints[f].empty();
    for (size_t j = 0; j < input.joint_names.size(); ++j) {
      frames << ",";
      if (has) frames << FormatDouble(input.joints[f].at(j));
    }
    frames << "\n";
    std::vector<std::string> labels;
    for (size_t c = 0; c < cameras.size(); ++c)
      labels.push_back(std::to_string(c));
    tables.Add(f, frame, labels);
  }
  WriteFileAtomic(dir + "/truth.csv", tables.TruthCsv());
  WriteFileAtomic(dir + "/corners.csv", tables.CornersCsv());
  WriteFileAtomic(dir + "/frames.csv", frames.str());
  std::ostringstream yaml;
  yaml << "# written by " << ToolVersion() << ": " << CommandLine() << "\n"
       << "kincal_session: 1\n"
       << "status: complete\n"
       << "frames: " << n << "\n"
       << "source: rendered (kincal synth, seed " << seed << ")\n"
       << "images: {";
  for (const std::string& name : cameras) {
    yaml << name << ": " << name << "/*.png, ";
  }
  yaml << "format: png}\n"
       << "frames_csv: frames.csv\n"
       << "joints: [";
  for (size_t j = 0; j < input.joint_names.size(); ++j) {
    yaml << (j ? ", " : "") << input.joint_names[j];
  }
  yaml << "]\n";
  // A raw mosaic's pattern, as capture records it (data/session.h).
  if (options.bayer && options.bayer_raw) {
    yaml << "sources:\n";
    for (const std::string& name : cameras) {
      yaml << "  " << name << ": {mosaic: RGGB}\n";
    }
  }
  WriteFileAtomic(dir + "/session.yaml", yaml.str());
  return static_cast<int>(n);
}

}  // namespace kincal
