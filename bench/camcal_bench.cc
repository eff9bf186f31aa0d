// Timings of camera calibration on OpenCV's 13 stereo pairs (9x6 board):
// chessboard detection, the Ceres refinement alone, and the full
// CalibrateCameras (with covariance and even/odd cross-validation). Prints
// the calibration figures once. Skips when ../shared/data is absent.

#include <benchmark/benchmark.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "camcal/calibrate_cameras.h"
#include "vision/calib_target.h"

namespace kincal {
namespace {

std::string StereoDir() {
  const char* env = std::getenv("KINCAL_SHARED_DATA");
  return std::string(env ? env : KINCAL_SHARED_DATA_DIR) +
         "/opencv-stereo-left-right";
}

const char* kIds[] = {"01", "02", "03", "04", "05", "06", "07",
                      "08", "09", "11", "12", "13", "14"};

bool HaveData() {
  struct stat st;
  return ::stat(StereoDir().c_str(), &st) == 0;
}

std::vector<cv::Mat> Images() {
  std::vector<cv::Mat> images;
  for (const char* id : kIds) {
    for (const char* side : {"left", "right"}) {
      images.push_back(cv::imread(StereoDir() + "/" + side + id + ".jpg",
                                  cv::IMREAD_GRAYSCALE));
    }
  }
  return images;
}

CalibrationProblem Problem(const std::vector<cv::Mat>& images) {
  CalibTargetDetector detector(ParseCalibTargetSpec("chessboard:9x6:1"));
  CalibrationProblem problem;
  problem.cameras = {{"left", 640, 480, 0, 0, 0, 0, {}},
                     {"right", 640, 480, 0, 0, 0, 0, {}}};
  for (size_t i = 0; i < images.size(); i += 2) {
    problem.views.push_back(
        {kIds[i / 2],
         {detector.Detect(images[i]), detector.Detect(images[i + 1])}});
  }
  return problem;
}

void BM_DetectChessboard26Images(benchmark::State& state) {
  if (!HaveData()) {
    state.SkipWithError("shared data not found");
    return;
  }
  const std::vector<cv::Mat> images = Images();
  for (auto _ : state) benchmark::DoNotOptimize(Problem(images));
  state.counters["images_per_s"] =
      benchmark::Counter(static_cast<double>(images.size()),
                         benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_DetectChessboard26Images)->Unit(benchmark::kMillisecond);

void BM_CalibrateStereo(benchmark::State& state) {
  if (!HaveData()) {
    state.SkipWithError("shared data not found");
    return;
  }
  const CalibrationProblem problem = Problem(Images());
  CalibrationOptions options;
  options.compute_covariance = state.range(0) != 0;
  options.cross_validate = state.range(0) != 0;
  CalibrationSummary sum;
  for (auto _ : state) sum = CalibrateCameras(problem, options);
  state.counters["rms_px"] = sum.rms_px;
  state.counters["baseline"] = sum.baseline;
  state.counters["iterations"] = sum.iterations;
  if (state.range(0)) {
    std::printf(
        "stereo: rms %.4f px (left %.4f, right %.4f), baseline %.4f +- %.4f "
        "squares, held-out %.4f / %.4f px, even/odd projection diff %.3f / "
        "%.3f px, %s in %d iterations\n",
        sum.rms_px, sum.cameras[0].rms_px, sum.cameras[1].rms_px, sum.baseline,
        sum.baseline_sigma, sum.cameras[0].holdout_rms_px,
        sum.cameras[1].holdout_rms_px, sum.cameras[0].half_diff_rms_px,
        sum.cameras[1].half_diff_rms_px, sum.termination.c_str(),
        sum.iterations);
  }
}
// 0: refinement only (OpenCV init + Ceres); 1: + covariance + cross-validation.
BENCHMARK(BM_CalibrateStereo)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace kincal

BENCHMARK_MAIN();
