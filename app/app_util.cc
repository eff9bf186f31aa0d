#include "app/app_util.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>

#include "calib/pose_coverage.h"
#include "data/error.h"
#include "data/observation_checks.h"

namespace kincal::app {

CLI::Option* AddRobotOptions(CLI::App* sub, std::string* robot,
                             std::string* root, std::string* tip,
                             const std::string& robot_help,
                             const std::string& root_help,
                             const std::string& tip_help) {
  CLI::Option* robot_option = sub->add_option("--robot", *robot, robot_help);
  sub->add_option("--root", *root, root_help);
  sub->add_option("--tip", *tip, tip_help);
  return robot_option;
}

std::string HelpFooter(const std::string& example,
                       const std::string& units_note) {
  return example + "\nUnits: lengths mm, angles deg, time s (pixels px)" +
         units_note + ". Defaults are shown beside each option.";
}

CLI::Option* AddCameraOption(CLI::App* sub, std::vector<std::string>* cameras,
                             const std::string& help) {
  return sub->add_option("--camera", *cameras, help)
      ->type_name("NAME=GLOB")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

std::vector<CameraGlob> CameraGlobs(const std::vector<std::string>& cameras,
                                    const std::string& left,
                                    const std::string& right) {
  std::vector<CameraGlob> out;
  if (!cameras.empty()) {
    if (!left.empty() || !right.empty()) {
      throw InputError(
          "--camera NAME=GLOB replaces --left/--right (their two-camera "
          "spelling); give one or the other");
    }
    for (const std::string& c : cameras) {
      const size_t eq = c.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == c.size()) {
        throw InputError("--camera '" + c +
                         "': expected NAME=GLOB, the camera's name in "
                         "rig.yaml and its images (quote the glob), e.g. "
                         "--camera top='session/top/*.png'");
      }
      const std::string name = c.substr(0, eq);
      for (const CameraGlob& g : out) {
        if (g.name == name) {
          throw InputError("--camera " + name + " is given twice");
        }
      }
      out.push_back({name, c.substr(eq + 1), "--camera " + name});
    }
    return out;
  }
  if (!right.empty() && left.empty()) {
    throw InputError("--right needs --left (the rig's first camera)");
  }
  if (!left.empty()) out.push_back({"left", left, "--left"});
  if (!right.empty()) out.push_back({"right", right, "--right"});
  return out;
}

std::vector<CameraGlob> InRigOrder(const std::vector<CameraGlob>& globs,
                                   const std::vector<std::string>& rig_names,
                                   const std::string& rig_file) {
  const bool spelled_left_right = !globs.empty() && globs[0].option == "--left";
  std::vector<CameraGlob> out;
  if (spelled_left_right) {
    if (globs.size() != rig_names.size()) {
      throw InputError(
          rig_file + " has " + std::to_string(rig_names.size()) +
          " cameras but --left/--right give " + std::to_string(globs.size()) +
          (rig_names.size() > 2 ? "; name every camera with --camera NAME=GLOB"
                                : ""));
    }
    for (size_t c = 0; c < globs.size(); ++c) {
      out.push_back(globs[c]);
      out.back().name = rig_names[c];
    }
    return out;
  }
  for (const std::string& name : rig_names) {
    const CameraGlob* found = nullptr;
    for (const CameraGlob& g : globs) {
      if (g.name == name) found = &g;
    }
    if (found == nullptr) {
      throw InputError("camera '" + name + "' of " + rig_file +
                       " has no images: give --camera " + name +
                       "='GLOB' for every camera of the rig");
    }
    out.push_back(*found);
  }
  for (const CameraGlob& g : globs) {
    if (std::find(rig_names.begin(), rig_names.end(), g.name) ==
        rig_names.end()) {
      std::string names;
      for (const std::string& n : rig_names)
        names += (names.empty() ? "" : ", ") + n;
      throw InputError(g.option + ": no camera '" + g.name + "' in " +
                       rig_file + " (its cameras: " + names + ")");
    }
  }
  return out;
}

void MakeDirs(const std::string& dir) {
  std::string path;
  for (size_t i = 0; i <= dir.size(); ++i) {
    if (i == dir.size() || dir[i] == '/') {
      if (!path.empty() && ::mkdir(path.c_str(), 0755) != 0 &&
          errno != EEXIST) {
        throw InputError(
            path, 0, 0,
            std::string("cannot create folder: ") + std::strerror(errno));
      }
    }
    if (i < dir.size()) path += dir[i];
  }
}

nlohmann::json Number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json StatsJson(const ErrorStats& s) {
  return {{"n", s.n},
          {"rms_mm", Number(s.rms_mm)},
          {"mean_mm", Number(s.mean_mm)},
          {"max_mm", Number(s.max_mm)},
          {"std_mm", Number(s.std_mm)}};
}

nlohmann::json ParametersJson(const FitSummary& fit,
                              const ModelState& nominal) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t i = 0; i < fit.params.size(); ++i) {
    const ParamInfo& p = fit.params[i];
    nlohmann::json j = {{"name", p.name},
                        {"value", Number(fit.values[i])},
                        {"sigma", Number(fit.sigmas[i])},
                        {"unit", p.InterfaceUnit()}};
    if (p.kind == ParamKind::kRow) {
      j["nominal"] = Number(p.ToInterface(ParamValue(nominal, p)));
    }
    out.push_back(j);
  }
  return out;
}

nlohmann::json OutliersJson(const std::vector<RowOutlier>& outliers) {
  nlohmann::json out = nlohmann::json::array();
  for (const RowOutlier& o : outliers) {
    nlohmann::json j = {{"pose", o.pose},
                        {"row", o.row},
                        {"error_mm", Number(o.error_mm)},
                        {"sigmas", Number(o.sigmas)},
                        {"excluded", o.excluded},
                        {"heldout", o.heldout}};
    if (!o.near_point.empty()) {
      j["near_point"] = o.near_point;
      j["near_point_mm"] = Number(o.near_point_mm);
    }
    out.push_back(j);
  }
  return out;
}

void PrintOutliers(const std::vector<RowOutlier>& outliers,
                   double axis_sigma_mm, double sigmas) {
  if (outliers.empty()) return;
  std::printf(
      "  %zu row(s) beyond %g robust sigmas (sigma %.4f mm per axis, from "
      "the median error): gross errors of the data, or poses where the "
      "model fails\n",
      outliers.size(), sigmas, axis_sigma_mm);
  for (const RowOutlier& o : outliers) {
    std::printf("    %s (data row %d%s): %.3f mm, %.0f sigma, %s",
                o.pose.c_str(), o.row + 1, o.heldout ? ", held out" : "",
                o.error_mm, o.sigmas,
                o.excluded ? "left out" : "kept (too many to leave out)");
    if (!o.near_point.empty()) {
      std::printf("; %.3f mm from %s: saved under the wrong label?",
                  o.near_point_mm, o.near_point.c_str());
    }
    std::printf("\n");
  }
}

Observations ReadCheckedObservations(const std::string& path,
                                     const Robot& robot,
                                     const std::string& robot_file,
                                     Warnings* warnings) {
  Observations obs = ReadObservationsCsv(path, robot.JointNames());
  CheckObservationsAgainstRobot(robot, obs, robot_file, warnings);
  return obs;
}

void AddWarnings(const std::vector<Warning>& warnings, nlohmann::json* j) {
  if (warnings.empty()) return;
  nlohmann::json list = nlohmann::json::array();
  for (const Warning& w : warnings)
    list.push_back({{"code", w.code}, {"message", w.message}});
  (*j)["warnings"] = list;
}

Warnings CommandWarnings() { return Warnings(&std::cerr); }

CLI::Option* AddBayerOption(CLI::App* sub, std::string* pattern) {
  return sub->add_option(
      "--bayer", *pattern,
      "the images are a colour camera's raw Bayer mosaic "
      "(GenICam BayerRG8 = RGGB; RGGB, GRBG, GBRG, BGGR): each "
      "pixel phase is white-balanced to gray from the image "
      "itself, no demosaic blur (none = gray images; default: "
      "what the session's session.yaml records, else none)");
}

BayerPattern ChooseBayerPattern(const std::string& option,
                                const std::vector<std::string>& session_mosaics,
                                const std::string& session_dir,
                                Warnings* warnings) {
  std::string recorded;
  for (size_t c = 0; c < session_mosaics.size(); ++c) {
    if (c > 0 && session_mosaics[c] != session_mosaics[0]) {
      throw InputError(
          session_dir +
          "/session.yaml: the cameras record different raw "
          "mosaics (sources.<camera>.mosaic: '" +
          session_mosaics[0] + "' and '" + session_mosaics[c] +
          "'); kincal reads one pattern for all cameras: record them in one "
          "pixel format, or give --bayer PATTERN to override");
    }
    recorded = session_mosaics[0];
  }
  if (!option.empty()) {
    const BayerPattern given = ParseBayerPattern(option);
    // A session.yaml without a pattern says nothing (recorded elsewhere,
    // or before capture recorded it): --bayer then stands alone.
    if (!recorded.empty() && given != ParseBayerPattern(recorded)) {
      warnings->Add("bayer_differs_from_session",
                    "--bayer " + option + " overrides " + session_dir +
                        "/session.yaml, which records raw " + recorded +
                        " mosaics (sources.<camera>.mosaic); if capture "
                        "recorded these images, drop --bayer");
    }
    return given;
  }
  if (recorded.empty()) return BayerPattern::kNone;
  std::cerr << "reading the images as raw " << recorded << " mosaics ("
            << session_dir << "/session.yaml sources.<camera>.mosaic; "
            << "--bayer none to read them as gray)\n";
  return ParseBayerPattern(recorded);
}

void WarnDoubtfulBayer(int doubtful, int images, BayerPattern pattern,
                       Warnings* warnings) {
  if (doubtful == 0) return;
  warnings->Add(
      "bayer_balance_doubtful",
      std::to_string(doubtful) + " of " + std::to_string(images) +
          " images do not look like a raw " + BayerPatternName(pattern) +
          " mosaic (its two green phases differ by more than 10 %, or no "
          "bright flat paper to balance on); their corners may be off. "
          "Check the camera's pixel format (--bayer none for gray or "
          "demosaiced images)");
}

void WarnRawMosaic(int cameras, Warnings* warnings) {
  if (cameras == 0) return;
  warnings->Add("images_look_raw_bayer",
                std::to_string(cameras) +
                    " cameras' images look like a colour camera's raw Bayer "
                    "mosaic read as gray (neighbouring pixels of flat paper "
                    "differ by more than 15 %): the corners are then far off. "
                    "Name the pattern with --bayer (GenICam BayerRG8 = RGGB)");
}

void WarnDemosaiced(int cameras, Warnings* warnings) {
  if (cameras == 0) return;
  warnings->Add(
      "images_demosaiced",
      std::to_string(cameras) +
          " cameras' images look demosaiced by the camera (their Bayer "
          "pixel phases differ in sharpness): on our renders the bundle's "
          "robot comes out about 1.2x worse from demosaiced images than from "
          "the raw mosaic, and a demosaic other than bilinear is not "
          "modelled (docs/VISION.md). Record the raw mosaic (capture "
          "URI bayer=raw; GenICam BayerRG8, V4L2 RGGB) and it is read as "
          "such");
}

void WarnPoseCoverage(const Robot& nominal, const Observations& obs,
                      Warnings* warnings) {
  const PoseCoverage coverage = CheckPoseCoverage(nominal, obs);
  if (!coverage.ok()) {
    warnings->Add("poses_leave_robot_undetermined",
                  PoseCoverageMessage(coverage));
  }
}

void RefuseBlindCameras(const std::vector<int>& tag_counts,
                        const std::vector<std::string>& cameras,
                        const std::vector<std::string>& images,
                        const std::string& rig_file,
                        const std::string& frames) {
  KINCAL_CHECK(
      cameras.size() == tag_counts.size() && images.size() == tag_counts.size(),
      "one name and one image source per camera");
  if (std::count(tag_counts.begin(), tag_counts.end(), 0) ==
      static_cast<long>(tag_counts.size())) {
    return;
  }
  for (size_t c = 0; c < tag_counts.size(); ++c) {
    if (tag_counts[c] > 0) continue;
    throw InputError("camera '" + cameras[c] + "' of " + rig_file + " (" +
                     images[c] + ") never shows a tag of the target in " +
                     frames +
                     ": check that these are its images and that it looks "
                     "at the target, or leave the camera out of the rig");
  }
}

}  // namespace kincal::app
