#include "capture/step_and_shoot.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>

#include "capture/frame_source.h"
#include "capture/robot_link.h"
#include "data/atomic_file.h"
#include "data/provenance.h"

namespace kincal::capture {
namespace {

void AppendValues(const std::vector<double>& q, std::string* row) {
  char buf[64];
  for (double v : q) {
    std::snprintf(buf, sizeof(buf), ",%.10g", v);
    *row += buf;
  }
  *row += "\n";
}

}  // namespace

StereoFrame AveragePairs(const std::vector<StereoFrame>& pairs) {
  StereoFrame out = pairs.back();
  for (int side = 0; side < 2; ++side) {
    cv::Mat sum;
    double t = 0;
    for (const StereoFrame& p : pairs) {
      const Frame& f = side == 0 ? p.left : p.right;
      cv::Mat f32;
      f.image.convertTo(f32, CV_32F);
      if (sum.empty()) {
        sum = f32;
      } else {
        sum += f32;
      }
      t += f.timestamp_s;
    }
    Frame& o = side == 0 ? out.left : out.right;
    sum.convertTo(o.image, CV_8U, 1.0 / pairs.size());
    o.timestamp_s = t / pairs.size();
  }
  return out;
}

StepAndShootResult RunStepAndShoot(StereoGrabber* grabber, bool live,
                                   const StepAndShootOptions& options) {
  StepAndShootResult result;
  auto fail = [&](StepAndShootResult::Outcome outcome, std::string message) {
    result.outcome = outcome;
    result.message = std::move(message);
    return result;
  };
  auto interrupted = [&] {
    return options.interrupted != nullptr && options.interrupted->load();
  };
  const std::vector<std::string>& names = options.joint_names;
  RobotLink link;
  Status s = link.Listen(options.listen);
  if (!s.ok()) {
    return fail(s.kind() == Status::Kind::kUnsupported
                    ? StepAndShootResult::kBadInput
                    : StepAndShootResult::kFailure,
                "--robot-listen: " + s.message());
  }
  if (options.announce) {
    std::cerr << "kincal capture: waiting for the robot on port " << link.port()
              << "\n";
  }
  s = link.Accept(options.timeout_s);
  if (!s.ok()) return fail(StepAndShootResult::kFailure, s.ToString());
  // HELLO: validated before anything is written.
  std::vector<int> order;  // HELLO position -> robot joint index
  s = ReceiveHello(&link, names, options.robot_file, options.timeout_s, &order,
                   &result.robot_name);
  if (!s.ok()) {
    return fail(s.kind() == Status::Kind::kUnsupported
                    ? StepAndShootResult::kBadInput
                    : StepAndShootResult::kFailure,
                s.message() + " (nothing written)");
  }

  SessionInfo info = options.info;
  info.joint_names = names;
  info.settings["mode"] = "step_and_shoot";
  info.settings["shots_per_pose"] = std::to_string(options.shots);
  info.settings["robot"] = result.robot_name;
  SessionRecorder recorder(options.recorder);
  s = recorder.Open(options.out, info);
  if (!s.ok()) {
    link.WriteLine("ERROR cannot create the session");
    return fail(StepAndShootResult::kFailure, s.ToString());
  }
  result.session_created = true;
  link.WriteLine("OK kincal 1");

  const auto start = std::chrono::steady_clock::now();
  std::string line, error, failure, bad_input;
  long last_pose = -1;
  int line_number = 1;
  std::string stream_csv = "t", obs_csv = "# " + CommandLine() + "\npose";
  for (const std::string& n : names) {
    stream_csv += "," + n;
    obs_csv += "," + n;
  }
  stream_csv += "\n";
  obs_csv += "\n";
  for (;;) {
    if (interrupted()) {
      result.stop_reason = "interrupted";
      break;
    }
    // Short reads so Ctrl-C is seen; the total wait is timeout_s.
    double waited = 0;
    do {
      s = link.ReadLine(0.25, &line);
      waited += 0.25;
    } while (s.kind() == Status::Kind::kTimeout && !interrupted() &&
             waited < options.timeout_s);
    if (interrupted()) continue;
    if (s.kind() == Status::Kind::kTimeout) {
      failure = "no message from the robot for " +
                std::to_string(static_cast<int>(options.timeout_s)) + " s";
      break;
    }
    if (!s.ok()) {
      failure = "robot link lost after " + std::to_string(result.poses) +
                " poses (last pose " + std::to_string(last_pose) +
                ") without BYE: " + s.message();
      break;
    }
    ++line_number;
    RobotMessage m;
    if (!ParseRobotMessage(line, static_cast<int>(names.size()), &m, &error)) {
      bad_input = "robot link, line " + std::to_string(line_number) + " '" +
                  line + "': " + error;
      link.WriteLine("ERROR " + error);
      break;
    }
    if (m.kind == RobotMessage::kBye) {
      result.stop_reason = "robot_bye";
      break;
    }
    if (m.kind == RobotMessage::kHello) {
      bad_input = "robot link, line " + std::to_string(line_number) +
                  ": a second HELLO";
      link.WriteLine("ERROR a second HELLO");
      break;
    }
    std::vector<double> q(names.size());
    for (size_t k = 0; k < order.size(); ++k) q[order[k]] = m.values[k];
    if (m.kind == RobotMessage::kJoints) {
      char buf[64];
      std::snprintf(buf, sizeof(buf), "%.6f", m.t);
      stream_csv += buf;
      AppendValues(q, &stream_csv);
      result.joint_stream = true;
      continue;
    }
    // SETTLED: `shots` pairs taken after the message arrived.
    const double settled_at = MonotonicSeconds();
    std::vector<StereoFrame> shots;
    while (static_cast<int>(shots.size()) < options.shots) {
      StereoFrame pair;
      s = grabber->Grab(&pair);
      if (!s.ok()) break;
      if (live && std::max(pair.left.timestamp_s, pair.right.timestamp_s) <
                      settled_at) {
        continue;  // taken before the robot had settled
      }
      shots.push_back(std::move(pair));
    }
    if (!s.ok()) {
      failure = "grab at pose " + std::to_string(m.pose) + ": " + s.ToString();
      link.WriteLine("ERROR camera: " + s.message());
      break;
    }
    s = recorder.Write(AveragePairs(shots), q);
    if (!s.ok()) {
      failure = "write: " + s.ToString();
      link.WriteLine("ERROR recording: " + s.message());
      break;
    }
    ++result.poses;
    last_pose = m.pose;
    obs_csv += std::to_string(m.pose);
    AppendValues(q, &obs_csv);
    s = link.WriteLine("DONE " + std::to_string(m.pose) + " " +
                       std::to_string(shots.size()));
    if (!s.ok()) {
      failure = "robot link lost after pose " + std::to_string(m.pose) + ": " +
                s.message();
      break;
    }
  }
  link.Close();
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  auto write = [&](const std::string& name, const std::string& text) {
    try {
      WriteFileAtomic(options.out + "/" + name, text);
    } catch (const std::exception& e) {
      if (failure.empty()) failure = e.what();
    }
  };
  write("observations.csv", obs_csv);
  if (result.joint_stream) write("joints.csv", stream_csv);
  SessionSummary summary;
  summary.complete = failure.empty() && bad_input.empty();
  summary.stop_reason = !failure.empty()     ? failure
                        : !bad_input.empty() ? bad_input
                                             : result.stop_reason;
  summary.dropped_left = grabber->dropped_left();
  summary.dropped_right = grabber->dropped_right();
  summary.seconds = result.seconds;
  const Status fin = recorder.Finalize(summary);
  if (!fin.ok() && failure.empty()) failure = "finalize: " + fin.ToString();
  result.frames = recorder.frames();
  result.stop_reason = summary.stop_reason;
  result.complete = failure.empty() && bad_input.empty();
  const std::string kept = " (the " + std::to_string(result.frames) +
                           " poses recorded so far are kept in " + options.out +
                           ")";
  if (!bad_input.empty()) {
    return fail(StepAndShootResult::kBadInput, bad_input + kept);
  }
  if (!failure.empty()) {
    return fail(StepAndShootResult::kFailure, failure + kept);
  }
  return result;
}

}  // namespace kincal::capture
