#ifndef KINCAL_TESTS_TESTING_JOINT_LOG_SESSION_H_
#define KINCAL_TESTS_TESTING_JOINT_LOG_SESSION_H_

// A recorded stereo session and a controller joint log of a two-joint robot
// for the tests of `capture --joints`: the images show a bright block that
// follows joint 1; the log is on the controller clock, kOffset s before the
// frames' (frame time = log time + kOffset).

#include <algorithm>
#include <cstdio>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "data/atomic_file.h"
#include "tests/testing/paths.h"

namespace kincal::testing {

constexpr double kFps = 30;
constexpr int kFrames = 450;           // 15 s
constexpr double kLogStart = 5000.0;   // controller clock
constexpr double kOffset = -5002.266;  // frame (media) time = log + offset

// Irregular stop-and-go of two joints (deg): 40 moves of 8 deg, each taking
// move_s after a dwell of 0.8-1.6 s drawn with `seed`.
struct StopAndGo {
  std::vector<double> starts, dwells;
  double move;
  explicit StopAndGo(unsigned seed = 5, double move_s = 0.8) : move(move_s) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> dwell(0.8, 1.6);
    double t = 0;
    for (int n = 0; n < 40; ++n) {
      starts.push_back(t);
      dwells.push_back(dwell(rng));
      t += dwells.back() + move;
    }
  }
  // Seconds since the robot last stopped (the start of the current dwell).
  double SinceStop(double t) const {
    const int n = Step(t);
    return t - kLogStart - starts[n];
  }
  // The joint values at log time t; true while the robot moves.
  bool At(double t, double* j1, double* j2) const {
    const int n = Step(t);
    const double r = t - kLogStart - starts[n];
    const double moved =
        r < dwells[n] ? 0.0 : std::min(r - dwells[n], move) * 8.0 / move;
    *j1 = 8.0 * n + moved;
    *j2 = 30 - 0.5 * *j1;
    return r >= dwells[n] && r < dwells[n] + move;
  }

 private:
  int Step(double t) const {
    return static_cast<int>(
        std::upper_bound(starts.begin(), starts.end(), t - kLogStart) -
        starts.begin() - 1);
  }
};

struct JointLogSession {
  std::string dir, robot, log;  // images l_*.png / r_*.png in dir
};

struct JointLogSessionOptions {
  std::string log_header = "t,j1,j2";
  double log_seconds = 40;  // 125 Hz from kLogStart
  // Applied to every logged row (row index, j1, j2) before it is written.
  std::function<void(int, double*, double*)> edit;
  // A second object moves in view all the time except in the first 0.6 s
  // after each stop of the robot.
  bool distractor = false;
};

// Images of `seen`'s motion and a log of `logged`'s, plus robot.yaml.
inline JointLogSession MakeJointLogSession(
    const std::string& tag, const StopAndGo& seen, const StopAndGo& logged,
    const JointLogSessionOptions& options = {}) {
  JointLogSession f;
  f.dir = MakeTempDir(tag);
  for (int k = 0; k < kFrames; ++k) {
    double j1, j2;
    seen.At(k / kFps - kOffset, &j1, &j2);
    cv::Mat img(120, 320, CV_8UC1, cv::Scalar(90));
    cv::rectangle(img, cv::Rect(static_cast<int>(j1 * 4) % 280, 30, 24, 40),
                  cv::Scalar(220), cv::FILLED);
    if (options.distractor && seen.SinceStop(k / kFps - kOffset) >= 0.6) {
      cv::rectangle(img, cv::Rect((k * 7) % 280, 80, 24, 30), cv::Scalar(30),
                    cv::FILLED);
    }
    cv::Mat noise(img.size(), CV_8UC1);
    cv::randu(noise, 0, 3);
    img += noise;
    char name[64];
    std::snprintf(name, sizeof(name), "/l_%04d.png", k);
    cv::imwrite(f.dir + name, img);
    std::snprintf(name, sizeof(name), "/r_%04d.png", k);
    cv::imwrite(f.dir + name, img);
  }
  std::ostringstream log;
  log.precision(12);
  log << options.log_header << "\n";
  for (int i = 0; i <= static_cast<int>(options.log_seconds * 125); ++i) {
    const double t = kLogStart + i / 125.0;
    double j1, j2;
    logged.At(t, &j1, &j2);
    if (options.edit) options.edit(i, &j1, &j2);
    log << t << "," << j1 << "," << j2 << "\n";
  }
  f.log = f.dir + "/joints.csv";
  WriteFileAtomic(f.log, log.str());
  f.robot = f.dir + "/robot.yaml";
  WriteFileAtomic(f.robot,
                  "kincal_robot: 1\nname: two\nconvention: dh\njoints:\n"
                  "  - {name: j1, type: revolute, d: 0, alpha: 0, a: 300, "
                  "theta: 0, limits: [-10, 400]}\n"
                  "  - {name: j2, type: revolute, d: 0, alpha: 0, a: 200, "
                  "theta: 0, limits: [-200, 90]}\n"
                  "tool: {d: 0, alpha: 0, a: 50, theta: 0}\n");
  return f;
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TESTING_JOINT_LOG_SESSION_H_
