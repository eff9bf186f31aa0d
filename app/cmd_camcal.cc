// kincal camcal: intrinsics (and stereo extrinsics) from images of a
// chessboard or an AprilGrid; writes rig.yaml. A thin layer over
// vision/calib_target.h (detection) and camcal/calibrate_cameras.h.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "app/app_util.h"
#include "app/command.h"
#include "app/front_end.h"
#include "camcal/calibrate_cameras.h"
#include "camcal/cameramodel.h"
#include "camcal/plausibility.h"
#include "camcal/rig.h"
#include "data/error.h"
#include "data/glob.h"
#include "data/progress.h"
#include "data/session.h"
#include "vision/calib_target.h"

namespace kincal::app {
namespace {

struct CamcalArgs {
  std::string left, right, target, out;
  std::vector<std::string> cameras;  // --camera NAME=GLOB, in rig order
  int distortion = 5;
  std::string loss = "none";
  double loss_scale_px = 3.0;
  // Outlier rejection threshold (CalibrationOptions::reject_sigma; 0 = off).
  double reject_sigma = CalibrationOptions().reject_sigma;
  // Distortion regulariser weight (CalibrationOptions::regularization).
  double regularization = CalibrationOptions().regularization;
  // mrcal's lens regulariser weight (CalibrationOptions::lens_regularization).
  double lens_regularization = CalibrationOptions().lens_regularization;
  // Projection uncertainty: distance (target units; 0 = infinity) and the
  // valid-intrinsics threshold (px).
  double uncertainty_distance = 0;
  double valid_threshold_px = 1.0;
  std::string out_cameramodel;  // PREFIX: PREFIX-<camera>.cameramodel
  bool tiny_board = false;      // skip the board-in-metres checks
  bool board_warp = CalibrationOptions().board_warp;
  bool json = false;
};

cv::Mat ReadGray(const std::string& path) {
  cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (img.empty()) {
    throw InputError(path +
                     ": cannot read the image (missing, not an image, "
                     "or an unsupported format)");
  }
  return img;
}

nlohmann::json Nullable(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json PoseJson(const Rigid3& pose) {
  std::vector<double> r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r.push_back(pose.R(i, j));
  }
  return {{"R", r}, {"t", {pose.t.x(), pose.t.y(), pose.t.z()}}};
}

// The calibration options of the command line.
CalibrationOptions ResolveOptions(const CamcalArgs& args) {
  CalibrationOptions options;
  options.num_distortion = args.distortion;
  options.loss_scale_px = args.loss_scale_px;
  if (args.regularization < 0) {
    throw InputError("--regularize " + std::to_string(args.regularization) +
                     ": expected a weight >= 0 (0 = none)");
  }
  options.regularization = args.regularization;
  if (args.lens_regularization < 0) {
    throw InputError("--regularize-lens " +
                     std::to_string(args.lens_regularization) +
                     ": expected a weight >= 0 (0 = none)");
  }
  options.lens_regularization = args.lens_regularization;
  if (args.reject_sigma < 0) {
    throw InputError("--reject-sigma " + std::to_string(args.reject_sigma) +
                     ": expected a threshold >= 0 (0 = no rejection)");
  }
  options.reject_sigma = args.reject_sigma;
  options.board_warp = args.board_warp;
  if (args.loss == "huber") {
    options.loss = CalibrationOptions::Loss::kHuber;
  } else if (args.loss == "cauchy") {
    options.loss = CalibrationOptions::Loss::kCauchy;
  } else if (args.loss == "none") {
    options.loss = CalibrationOptions::Loss::kTrivial;
  } else {
    throw InputError("--loss '" + args.loss +
                     "': expected huber, cauchy or none");
  }
  if (args.uncertainty_distance < 0) {
    throw InputError("--uncertainty-distance " +
                     std::to_string(args.uncertainty_distance) +
                     ": expected a distance > 0 (or 0 for infinity)");
  }
  if (args.uncertainty_distance > 0) {
    options.uncertainty.distance = args.uncertainty_distance;
  }
  options.uncertainty.valid_threshold_px = args.valid_threshold_px;
  options.Check();
  return options;
}

// The cameras' names and image globs (--camera NAME=GLOB in rig order, or
// --left [--right]).
std::vector<CameraGlob> Globs(const CamcalArgs& args) {
  const std::vector<CameraGlob> globs =
      CameraGlobs(args.cameras, args.left, args.right);
  if (globs.empty()) {
    throw InputError(
        "give --camera NAME='GLOB' for every camera (the first is the "
        "reference), or --left 'GLOB' [--right 'GLOB']");
  }
  if (static_cast<int>(globs.size()) > kMaxCameras) {
    throw InputError("camcal takes at most " + std::to_string(kMaxCameras) +
                     " cameras, got " + std::to_string(globs.size()));
  }
  for (const CameraGlob& g : globs) CheckSessionCameraName(g.name, g.option);
  return globs;
}

// Image files per camera, paired by name order.
std::vector<std::vector<std::string>> ImageFiles(
    const std::vector<CameraGlob>& globs) {
  std::vector<std::vector<std::string>> files;
  for (const CameraGlob& g : globs) {
    files.push_back(GlobSortedOrThrow(g.glob, g.option));
    if (files.back().size() != files[0].size()) {
      throw InputError(globs[0].option + " matches " +
                       std::to_string(files[0].size()) + " images but " +
                       g.option + " matches " +
                       std::to_string(files.back().size()) +
                       "; the cameras' images are paired in name order");
    }
  }
  return files;
}

// Detects the target in every image; each camera takes the image size of
// its first image. InputError when sizes differ or a camera sees the target
// in fewer than options.min_views images. `lenses` (one per camera, or
// empty): the cameras' calibrated lenses, their AprilGrid tags' sides
// fitted where they are straight (CalibTargetDetector).
CalibrationProblem DetectTargets(
    const std::vector<CameraGlob>& globs, const CalibTargetSpec& spec,
    const CalibrationOptions& options,
    const std::vector<std::vector<std::string>>& files, Progress* progress,
    const std::vector<CameraIntrinsics>& lenses = {}) {
  const size_t nc = files.size();
  const size_t nv = files[0].size();
  CalibrationProblem problem;
  std::vector<std::unique_ptr<CalibTargetDetector>> detectors;
  for (size_t c = 0; c < nc; ++c) {
    problem.cameras.push_back({globs[c].name, 0, 0, 0, 0, 0, 0, {}});
    detectors.push_back(std::make_unique<CalibTargetDetector>(
        spec, lenses.empty() ? std::nullopt
                             : std::optional<CameraIntrinsics>(lenses[c])));
  }
  std::vector<int> found(nc, 0);
  for (size_t v = 0; v < nv; ++v) {
    progress->Update(static_cast<long>(v + 1), static_cast<long>(nv),
                     "detecting the target: view");
    CalibrationView view;
    view.label = files[0][v];
    for (size_t c = 0; c < nc; ++c) {
      const cv::Mat img = ReadGray(files[c][v]);
      CameraIntrinsics& cam = problem.cameras[c];
      if (cam.width == 0) {
        cam.width = img.cols;
        cam.height = img.rows;
      } else if (img.cols != cam.width || img.rows != cam.height) {
        throw InputError(
            files[c][v] + ": image is " + std::to_string(img.cols) + "x" +
            std::to_string(img.rows) + ", the camera's " + "other images are " +
            std::to_string(cam.width) + "x" + std::to_string(cam.height));
      }
      view.observations.push_back(detectors[c]->Detect(img));
      if (static_cast<int>(view.observations.back().pixels.size()) >=
          options.min_points_per_view) {
        ++found[c];
      }
    }
    problem.views.push_back(std::move(view));
  }
  for (size_t c = 0; c < nc; ++c) {
    if (found[c] < options.min_views) {
      throw InputError(globs[c].option + " '" + globs[c].glob + "': target " +
                       spec.text + " found in " + std::to_string(found[c]) +
                       " of " + std::to_string(nv) + " images; need at least " +
                       std::to_string(options.min_views));
    }
  }

  return problem;
}

// The calibrated cameras as lenses for a second detection (named and sized
// as the images), or empty when no camera has distortion.
std::vector<CameraIntrinsics> CalibratedLenses(
    const CalibrationProblem& problem, const CalibrationSummary& sum) {
  std::vector<CameraIntrinsics> lenses;
  bool distorted = false;
  for (size_t c = 0; c < sum.cameras.size(); ++c) {
    CameraIntrinsics lens = sum.cameras[c].intrinsics;
    lens.name = problem.cameras[c].name;
    lens.width = problem.cameras[c].width;
    lens.height = problem.cameras[c].height;
    for (double k : lens.distortion) distorted = distorted || k != 0;
    lenses.push_back(lens);
  }
  return distorted ? lenses : std::vector<CameraIntrinsics>{};
}

nlohmann::json PixelJson(const Eigen::Vector2d& pixel) {
  return {pixel.x(), pixel.y()};
}

// The projection uncertainty map (worst-direction sigma, px).
nlohmann::json UncertaintyJson(const ProjectionUncertaintyMap& map) {
  nlohmann::json corners = nlohmann::json::array();
  for (int k = 0; k < 4; ++k) {
    corners.push_back({{"pixel", PixelJson(map.corner_pixels[k])},
                       {"sigma_px", map.corner_px[k]}});
  }
  nlohmann::json region = nlohmann::json::array();
  for (const Eigen::Vector2d& p : map.valid_region)
    region.push_back(PixelJson(p));
  return {
      {"distance", Nullable(map.distance)},
      {"centre",
       {{"pixel", PixelJson(map.centre_pixel)}, {"sigma_px", map.centre_px}}},
      {"corners", corners},
      {"grid",
       {{"cols", map.cols}, {"rows", map.rows}, {"sigma_px", map.grid_px}}},
      {"valid_threshold_px", map.valid_threshold_px},
      {"valid_intrinsics_region", region}};
}

nlohmann::json CameraJson(const CalibrationSummary& sum, size_t c) {
  const CameraCalibrationSummary& cs = sum.cameras[c];
  const CameraIntrinsics& in = cs.intrinsics;
  nlohmann::json cj = {
      {"name", in.name},
      {"width", in.width},
      {"height", in.height},
      {"fx", in.fx},
      {"fy", in.fy},
      {"cx", in.cx},
      {"cy", in.cy},
      {"distortion", in.distortion},
      {"rms_px", cs.rms_px},
      {"max_px", cs.max_px},
      {"outliers", cs.outliers},
      {"opencv_rms_px", cs.opencv_rms_px},
      {"views_used", cs.num_views},
      {"points", cs.num_points},
      {"rejected_corners", cs.rejected_corners},
      {"rejected_views", cs.rejected_views},
      {"holdout_rms_px", Nullable(cs.holdout_rms_px)},
      {"half_diff_focus_radius_px", Nullable(cs.half_diff_focus_radius_px)},
      {"half_diff_focus_rms_px", Nullable(cs.half_diff_focus_rms_px)},
      {"half_diff_rms_px", Nullable(cs.half_diff_rms_px)},
      {"half_diff_max_px", Nullable(cs.half_diff_max_px)},
      {"cam_from_rig", PoseJson(sum.rig.cameras[c].cam_from_rig)}};
  if (!cs.sigma.empty()) {
    cj["sigma"] = {
        {"fx", cs.sigma[kFx]},
        {"fy", cs.sigma[kFy]},
        {"cx", cs.sigma[kCx]},
        {"cy", cs.sigma[kCy]},
        {"distortion",
         std::vector<double>(cs.sigma.begin() + kK1,
                             cs.sigma.begin() + kK1 + in.distortion.size())}};
    cj["projection_uncertainty"] = UncertaintyJson(cs.projection_uncertainty);
  }
  nlohmann::json per_view = nlohmann::json::array();
  for (double r : cs.view_rms_px) per_view.push_back(Nullable(r));
  cj["view_rms_px"] = per_view;
  const ImageResidualGrid& g = cs.image_grid;
  auto nullable = [](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double x : v) a.push_back(Nullable(x));
    return a;
  };
  cj["image_grid"] = {{"cols", g.cols},
                      {"rows", g.rows},
                      {"cell_w_px", g.cell_w_px},
                      {"cell_h_px", g.cell_h_px},
                      {"count", g.count},
                      {"rms_px", nullable(g.rms_px)},
                      {"mean_dx_px", nullable(g.mean_dx_px)},
                      {"mean_dy_px", nullable(g.mean_dy_px)}};
  return cj;
}

// PREFIX-<camera>.cameramodel per camera.
std::vector<std::string> CameraModelPaths(const CamcalArgs& args,
                                          const CalibrationSummary& sum) {
  std::vector<std::string> paths;
  for (const Camera& cam : sum.rig.cameras) {
    paths.push_back(args.out_cameramodel + "-" + cam.intrinsics.name +
                    ".cameramodel");
  }
  return paths;
}

// mrcal models of the solved rig: extrinsics cam_from_rig in target units
// (mrcal's convention: the units of the board), the valid intrinsics region
// from the projection uncertainty.
void WriteCameraModels(const CamcalArgs& args, const CalibrationSummary& sum) {
  const std::vector<CameraModelFile> models =
      CameraModelsFromRig(sum.rig, /*unit_mm=*/1.0);
  const std::vector<std::string> paths = CameraModelPaths(args, sum);
  for (size_t c = 0; c < models.size(); ++c) {
    WriteCameraModel(paths[c], models[c]);
  }
}

// The outlier rejection's settings and outcome over all cameras.
nlohmann::json OutlierRejectionJson(const CamcalArgs& args,
                                    const CalibrationSummary& sum) {
  int corners = 0, views = 0;
  for (const CameraCalibrationSummary& cs : sum.cameras) {
    corners += cs.rejected_corners;
    views += cs.rejected_views;
  }
  return {{"reject_sigma", args.reject_sigma},
          {"trigger_sigma",
           args.reject_sigma * CalibrationOptions().reject_trigger},
          {"rounds", sum.rejection_rounds},
          {"sigma_px", Nullable(sum.rejection_sigma_px)},
          {"corners", corners},
          {"views", views}};
}

nlohmann::json SummaryJson(const CamcalArgs& args, const CalibTargetSpec& spec,
                           const CalibrationProblem& problem,
                           const std::vector<std::vector<std::string>>& files,
                           const CalibrationSummary& sum) {
  const size_t nc = files.size();
  const size_t nv = files[0].size();
  nlohmann::json j;
  j["rms_px"] = sum.rms_px;
  j["baseline"] = sum.baseline;
  j["baseline_sigma"] = Nullable(sum.baseline_sigma);
  j["target"] = spec.text;
  j["out"] = args.out;
  j["unconnected"] = nlohmann::json::array();  // all connected, or exit 2
  if (!args.out_cameramodel.empty()) {
    nlohmann::json files = nlohmann::json::array();
    for (const std::string& f : CameraModelPaths(args, sum)) files.push_back(f);
    j["out_cameramodel"] = files;
  }
  j["views"] = nv;
  j["termination"] = sum.termination;
  j["converged"] = sum.converged;
  j["iterations"] = sum.iterations;
  j["regularization"] = {{"weight", args.regularization},
                         {"lens_weight", args.lens_regularization},
                         {"cost", sum.regularization_cost},
                         {"share", sum.regularization_share}};
  j["residual_sigma_px"] = sum.residual_sigma_px;
  j["outlier_rejection"] = OutlierRejectionJson(args, sum);
  if (args.board_warp) j["board_warp"] = sum.board_warp;
  j["seconds"] = sum.seconds;
  if (!sum.covariance_note.empty()) j["covariance_note"] = sum.covariance_note;
  nlohmann::json cams = nlohmann::json::array();
  for (size_t c = 0; c < nc; ++c) {
    cams.push_back(CameraJson(sum, c));
  }
  j["cameras"] = cams;
  if (nc == 2 && !sum.extrinsic_rotation_sigma_deg.empty()) {
    j["extrinsics_sigma"] = {{"rotation_deg", sum.extrinsic_rotation_sigma_deg},
                             {"translation", sum.extrinsic_translation_sigma}};
  }
  nlohmann::json images = nlohmann::json::array();
  for (size_t v = 0; v < nv; ++v) {
    nlohmann::json row;
    for (size_t c = 0; c < nc; ++c) {
      row[problem.cameras[c].name] = files[c][v];
    }
    images.push_back(row);
  }
  j["images"] = images;
  return j;
}

void PrintSummary(const CamcalArgs& args, const CalibTargetSpec& spec,
                  const CalibrationOptions& options,
                  const std::vector<std::vector<std::string>>& files,
                  const CalibrationSummary& sum) {
  const size_t nc = files.size();
  const size_t nv = files[0].size();
  std::printf("kincal camcal: %zu %s, target %s, %d distortion coefficients\n",
              nv, nc == 2 ? "stereo pairs" : "images", spec.text.c_str(),
              options.num_distortion);
  std::printf("  Ceres: %s after %d iterations, %.2f s\n",
              sum.termination.c_str(), sum.iterations, sum.seconds);
  if (sum.regularization_cost > 0) {
    std::printf(
        "  regularisers: k4..k6 weight %g, lens weight %g; %.3g of the "
        "cost\n",
        options.regularization, options.lens_regularization,
        sum.regularization_share);
  }
  for (size_t c = 0; c < nc; ++c) {
    const CameraCalibrationSummary& cs = sum.cameras[c];
    const CameraIntrinsics& in = cs.intrinsics;
    std::printf("  %s (%dx%d): fx %.3f fy %.3f cx %.3f cy %.3f",
                in.name.c_str(), in.width, in.height, in.fx, in.fy, in.cx,
                in.cy);
    if (!cs.sigma.empty()) {
      std::printf("  (sigma %.3f %.3f %.3f %.3f)", cs.sigma[kFx], cs.sigma[kFy],
                  cs.sigma[kCx], cs.sigma[kCy]);
    }
    std::printf("\n    distortion:");
    for (double d : in.distortion) std::printf(" %.6g", d);
    std::printf(
        "\n    %d views, %d points: RMS %.4f px (OpenCV %.4f), worst "
        "%.3f px, %d outliers\n",
        cs.num_views, cs.num_points, cs.rms_px, cs.opencv_rms_px, cs.max_px,
        cs.outliers);
    if (options.reject_sigma > 0) {
      std::printf(
          "    outlier rejection (%g sigma): %d corners, %d views dropped\n",
          options.reject_sigma, cs.rejected_corners, cs.rejected_views);
    }
    std::printf(
        "    cross-validation: held-out RMS %.4f px (inliers), even/odd "
        "projection difference RMS %.3f px within %.0f px of the centre, "
        "%.3f px over the image (max %.3f)\n",
        cs.holdout_rms_px, cs.half_diff_focus_rms_px,
        cs.half_diff_focus_radius_px, cs.half_diff_rms_px, cs.half_diff_max_px);
    double worst = 0;
    size_t worst_v = 0;
    for (size_t v = 0; v < cs.view_rms_px.size(); ++v) {
      if (std::isfinite(cs.view_rms_px[v]) && cs.view_rms_px[v] > worst) {
        worst = cs.view_rms_px[v];
        worst_v = v;
      }
    }
    std::printf("    worst view: %s (RMS %.4f px)\n", files[c][worst_v].c_str(),
                worst);
    if (!cs.sigma.empty()) {
      const ProjectionUncertaintyMap& u = cs.projection_uncertainty;
      std::printf(
          "    projection uncertainty (1 sigma, worst direction) at %s: "
          "centre %.3f px, corners %.3f %.3f %.3f %.3f px\n",
          std::isinf(u.distance)
              ? "infinity"
              : (std::to_string(u.distance) + " units").c_str(),
          u.centre_px, u.corner_px[0], u.corner_px[1], u.corner_px[2],
          u.corner_px[3]);
    }
  }
  if (options.board_warp) {
    std::printf("  board warp (x, y): %.5g %.5g target units\n",
                sum.board_warp[0], sum.board_warp[1]);
  }
  if (nc == 2) {
    std::printf("  baseline %.4f +- %.4f (target units)\n", sum.baseline,
                sum.baseline_sigma);
  }
  std::printf("  RMS %.4f px over all cameras; wrote %s\n", sum.rms_px,
              args.out.c_str());
}

// A camera that shares no board view with the reference (directly or
// through other cameras) has no pose in the rig: bad input, nothing
// written. With --json the object names them in `unconnected` (spec v3)
// beside the error.
void RefuseUnconnected(const CamcalArgs& args,
                       const CalibrationProblem& problem,
                       const CalibrationOptions& options) {
  const std::vector<int> unconnected = UnconnectedCameras(problem, options);
  if (unconnected.empty()) return;
  const std::string message = UnconnectedMessage(problem, unconnected);
  if (args.json) {
    nlohmann::json j;
    nlohmann::json names = nlohmann::json::array();
    for (int c : unconnected) names.push_back(problem.cameras[c].name);
    j["unconnected"] = names;
    j["error"] = message;
    j["out"] = nullptr;
    PrintJson(j);
  }
  throw InputError(message + "; nothing written");
}

int RunCamcal(const CamcalArgs& args) {
  // Everything that can be checked before reading images comes first.
  const CalibTargetSpec spec = ParseCalibTargetSpec(args.target);
  if (!args.tiny_board) {
    const std::string why = BoardSizeImplausible(spec.size, spec.text);
    if (!why.empty()) throw InputError(why);
  }
  const CalibrationOptions options = ResolveOptions(args);
  const std::vector<CameraGlob> globs = Globs(args);
  const std::vector<std::vector<std::string>> files = ImageFiles(globs);
  Progress progress("kincal camcal", args.json);
  CalibrationProblem problem =
      DetectTargets(globs, spec, options, files, &progress);
  RefuseUnconnected(args, problem, options);
  progress.Stage("calibrating (OpenCV start, Ceres refinement, covariance)");
  CalibrationSummary sum = CalibrateCameras(problem, options);
  // A distorted lens bends the AprilGrid tags' sides, and lines fitted in
  // the image meet off the corners (docs/CAMCAL.md): detected again with
  // the lenses just calibrated, the sides are fitted where they are
  // straight, and the cameras calibrated again from those corners.
  const std::vector<CameraIntrinsics> lenses = CalibratedLenses(problem, sum);
  const bool second_pass = spec.kind == CalibTargetSpec::Kind::kAprilGrid &&
                           sum.converged && !lenses.empty();
  if (second_pass) {
    problem = DetectTargets(globs, spec, options, files, &progress, lenses);
    progress.Stage("calibrating again from the corners the lenses straighten");
    sum = CalibrateCameras(problem, options);
  }
  progress.Done();
  const std::string failure = SolveFailure(sum, options);
  if (!failure.empty()) {
    std::cerr << "kincal: failure: " << failure << "; nothing written\n";
    return 1;
  }
  if (!args.tiny_board) {
    const std::string why = SolvedRigImplausible(sum, spec.size, spec.text);
    if (!why.empty()) throw InputError(why + "; nothing written");
  }
  WriteRigYaml(args.out, sum.rig);
  if (!args.out_cameramodel.empty()) WriteCameraModels(args, sum);
  if (args.json) {
    nlohmann::json j = SummaryJson(args, spec, problem, files, sum);
    j["detected_with_lenses"] = second_pass;
    PrintJson(j);
  } else {
    PrintSummary(args, spec, options, files, sum);
    if (second_pass) {
      std::printf(
          "  the AprilGrid detected again with these lenses: its tags' "
          "sides fitted where they are straight\n");
    }
  }
  return 0;
}

}  // namespace

void AddCamcalCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<CamcalArgs>();
  CLI::App* sub = app.add_subcommand("camcal", kCamcalDescription);
  AddCameraOption(sub, &args->cameras,
                  "NAME='GLOB': one camera's images (repeat for every camera, "
                  "in rig order: the first is the reference; images pair in "
                  "name order)");
  sub->add_option("--left", args->left,
                  "images of the first (reference) camera, a quoted glob "
                  "(the two-camera spelling of --camera left=GLOB)");
  sub->add_option("--right", args->right,
                  "images of the second camera (paired with --left in name "
                  "order); omit for one camera");
  sub->add_option("--target", args->target,
                  "chessboard:COLSxROWS:SQUARE (inner corners) or "
                  "aprilgrid:COLSxROWS:TAG_SIZE:SPACING_RATIO; sizes in mm")
      ->required();
  sub->add_option("--out", args->out, "rig.yaml to write")->required();
  sub->add_option("--distortion", args->distortion,
                  "distortion coefficients: 0, 4, 5 (default) or 8");
  sub->add_option("--regularize", args->regularization,
                  "distortion regulariser weight, mrcal-style (default "
                  "0.005; 0 = none)");
  sub->add_option("--regularize-lens", args->lens_regularization,
                  "mrcal's lens regulariser (distortion toward 0, principal "
                  "point toward the image centre), weight relative to "
                  "mrcal's (default 1; 0 = none)");
  sub->add_option("--loss", args->loss,
                  "loss on each corner: none (default, least squares on the "
                  "inliers), huber or cauchy");
  sub->add_option("--reject-sigma", args->reject_sigma,
                  "outlier rejection: drop corners beyond this many sigma "
                  "of the residuals, mrcal-style (default 4; 0 = none)");
  sub->add_option("--loss-scale", args->loss_scale_px,
                  "robust loss scale, px (default 3)");
  sub->add_option("--uncertainty-distance", args->uncertainty_distance,
                  "distance of the points whose projection uncertainty is "
                  "reported, target units (mm); 0 (default) = infinity");
  sub->add_option("--valid-threshold", args->valid_threshold_px,
                  "valid intrinsics region: where the projection "
                  "uncertainty stays below this, px (default 1)");
  sub->add_option("--out-cameramodel", args->out_cameramodel,
                  "also write mrcal models PREFIX-<camera>.cameramodel "
                  "(translations in target units)");
  sub->add_flag("--tiny-board", args->tiny_board,
                "the board really is this small (sizes in mm): skip the "
                "board-in-metres checks (a square or tag under 1 mm, the "
                "board seen within 20 mm, a baseline under 1 mm)");
  sub->add_flag("--board-warp,!--no-board-warp", args->board_warp,
                "estimate the board's deflection (mrcal's 2-parameter "
                "paraboloid, target units; default on, --no-board-warp for a "
                "flat board)");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example: stereo rig from a 9x6 chessboard with 25 mm squares:\n  kincal "
      "camcal --left 'calib/left*.png' --right 'calib/right*.png' --target "
      "chessboard:9x6:25 --out rig.yaml --json > rig.json\n  (rig.json beside "
      "rig.yaml feeds the camera section of kincal report)"));
  sub->callback([run, args] { *run = [args] { return RunCamcal(*args); }; });
}

}  // namespace kincal::app
