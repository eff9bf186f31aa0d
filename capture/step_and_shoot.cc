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

FrameSet AverageSets(const std::vector<FrameSet>& sets) {
  FrameSet out = sets.back();
  for (size_t c = 0; c < out.frames.size(); ++c) {
    cv::Mat sum;
    double t = 0;
    for (const FrameSet& set : sets) {
      const Frame& f = set.frames[c];
      cv::Mat f32;
      f.image.convertTo(f32, CV_32F);
      if (sum.empty()) {
        sum = f32;
      } else {
        sum += f32;
      }
      t += f.timestamp_s;
    }
    Frame& o = out.frames[c];
    sum.convertTo(o.image, CV_8U, 1.0 / sets.size());
    o.timestamp_s = t / sets.size();
  }
  return out;
}

namespace {

using Outcome = StepAndShootResult::Outcome;

bool Interrupted(const StepAndShootOptions& options) {
  return options.interrupted != nullptr && options.interrupted->load();
}

void SetOutcome(StepAndShootResult* result, Outcome outcome,
                std::string message) {
  result->outcome = outcome;
  result->message = std::move(message);
}

// Waits for the robot and checks its HELLO (nothing is written before it
// passes); `order` maps HELLO positions to robot joint indices. False with
// the result's outcome set when it does not pass.
bool ConnectRobot(const StepAndShootOptions& options, RobotLink* link,
                  std::vector<int>* order, StepAndShootResult* result) {
  Status s = link->Listen(options.listen);
  if (!s.ok()) {
    SetOutcome(result,
               s.kind() == Status::Kind::kUnsupported
                   ? StepAndShootResult::kBadInput
                   : StepAndShootResult::kFailure,
               "--robot-listen: " + s.message());
    return false;
  }
  if (options.announce) {
    std::cerr << "kincal capture: waiting for the robot on port "
              << link->port() << "\n";
  }
  s = link->Accept(options.timeout_s);
  if (!s.ok()) {
    SetOutcome(result, StepAndShootResult::kFailure, s.ToString());
    return false;
  }
  s = ReceiveHello(link, options.joint_names, options.robot_file,
                   options.timeout_s, order, &result->robot_name);
  if (!s.ok()) {
    SetOutcome(result,
               s.kind() == Status::Kind::kUnsupported
                   ? StepAndShootResult::kBadInput
                   : StepAndShootResult::kFailure,
               s.message() + " (nothing written)");
    return false;
  }
  return true;
}

// Short reads so Ctrl-C is seen; the total wait is timeout_s.
Status ReadMessageLine(const StepAndShootOptions& options, RobotLink* link,
                       std::string* line) {
  Status s;
  double waited = 0;
  do {
    s = link->ReadLine(0.25, line);
    waited += 0.25;
  } while (s.kind() == Status::Kind::kTimeout && !Interrupted(options) &&
           waited < options.timeout_s);
  return s;
}

// `shots` sets whose every frame was taken after `settled_at` (live
// sources; replay: the next sets).
Status GrabSettledSets(FrameGrabber* grabber, bool live, int shots,
                       double settled_at, std::vector<FrameSet>* sets) {
  while (static_cast<int>(sets->size()) < shots) {
    FrameSet set;
    const Status s = grabber->Grab(&set);
    if (!s.ok()) return s;
    const bool before =
        std::any_of(set.frames.begin(), set.frames.end(),
                    [&](const Frame& f) { return f.timestamp_s < settled_at; });
    if (live && before) continue;  // taken before the robot had settled
    sets->push_back(std::move(set));
  }
  return Status();
}

// What the pose loop leaves behind: the CSV texts and why it stopped.
struct PoseLoop {
  std::string stream_csv;  // joints.csv: the robot's J lines
  std::string obs_csv;     // observations.csv: one row per recorded pose
  std::string failure;     // robot, camera or disk failure
  std::string bad_input;   // a malformed robot message
};

PoseLoop StartPoseLoop(const std::vector<std::string>& names) {
  PoseLoop loop;
  loop.stream_csv = "t";
  loop.obs_csv = "# " + CommandLine() + "\npose";
  for (const std::string& n : names) {
    loop.stream_csv += "," + n;
    loop.obs_csv += "," + n;
  }
  loop.stream_csv += "\n";
  loop.obs_csv += "\n";
  return loop;
}

// SETTLED: grab, average and record one set with the readings, answer
// DONE. False (with loop->failure set) when the loop must stop.
bool ShootPose(const RobotMessage& m, const std::vector<double>& q,
               FrameGrabber* grabber, bool live,
               const StepAndShootOptions& options, RobotLink* link,
               SessionRecorder* recorder, PoseLoop* loop,
               StepAndShootResult* result, long* last_pose) {
  std::vector<FrameSet> shots;
  Status s =
      GrabSettledSets(grabber, live, options.shots, MonotonicSeconds(), &shots);
  if (!s.ok()) {
    loop->failure =
        "grab at pose " + std::to_string(m.pose) + ": " + s.ToString();
    link->WriteLine("ERROR camera: " + s.message());
    return false;
  }
  s = recorder->Write(AverageSets(shots), q);
  if (!s.ok()) {
    loop->failure = "write: " + s.ToString();
    link->WriteLine("ERROR recording: " + s.message());
    return false;
  }
  ++result->poses;
  *last_pose = m.pose;
  loop->obs_csv += std::to_string(m.pose);
  AppendValues(q, &loop->obs_csv);
  s = link->WriteLine("DONE " + std::to_string(m.pose) + " " +
                      std::to_string(shots.size()));
  if (!s.ok()) {
    loop->failure = "robot link lost after pose " + std::to_string(m.pose) +
                    ": " + s.message();
    return false;
  }
  return true;
}

// Reads the robot's messages until BYE, Ctrl-C, a malformed message or a
// failure: J lines go to joints.csv, each SETTLED records one pose.
PoseLoop RecordPoses(FrameGrabber* grabber, bool live,
                     const StepAndShootOptions& options,
                     const std::vector<int>& order, RobotLink* link,
                     SessionRecorder* recorder, StepAndShootResult* result) {
  const std::vector<std::string>& names = options.joint_names;
  PoseLoop loop = StartPoseLoop(names);
  std::string line, error;
  long last_pose = -1;
  int line_number = 1;
  for (;;) {
    if (Interrupted(options)) {
      result->stop_reason = "interrupted";
      break;
    }
    const Status s = ReadMessageLine(options, link, &line);
    if (Interrupted(options)) continue;
    if (s.kind() == Status::Kind::kTimeout) {
      loop.failure = "no message from the robot for " +
                     std::to_string(static_cast<int>(options.timeout_s)) + " s";
      break;
    }
    if (!s.ok()) {
      loop.failure = "robot link lost after " + std::to_string(result->poses) +
                     " poses (last pose " + std::to_string(last_pose) +
                     ") without BYE: " + s.message();
      break;
    }
    ++line_number;
    RobotMessage m;
    if (!ParseRobotMessage(line, static_cast<int>(names.size()), &m, &error)) {
      loop.bad_input = "robot link, line " + std::to_string(line_number) +
                       " '" + line + "': " + error;
      link->WriteLine("ERROR " + error);
      break;
    }
    if (m.kind == RobotMessage::kBye) {
      result->stop_reason = "robot_bye";
      break;
    }
    if (m.kind == RobotMessage::kHello) {
      loop.bad_input = "robot link, line " + std::to_string(line_number) +
                       ": a second HELLO";
      link->WriteLine("ERROR a second HELLO");
      break;
    }
    std::vector<double> q(names.size());
    for (size_t k = 0; k < order.size(); ++k) q[order[k]] = m.values[k];
    if (m.kind == RobotMessage::kJoints) {
      char buf[64];
      std::snprintf(buf, sizeof(buf), "%.6f", m.t);
      loop.stream_csv += buf;
      AppendValues(q, &loop.stream_csv);
      result->joint_stream = true;
      continue;
    }
    if (!ShootPose(m, q, grabber, live, options, link, recorder, &loop, result,
                   &last_pose)) {
      break;
    }
  }
  return loop;
}

}  // namespace

StepAndShootResult RunStepAndShoot(FrameGrabber* grabber, bool live,
                                   const StepAndShootOptions& options) {
  StepAndShootResult result;
  RobotLink link;
  std::vector<int> order;  // HELLO position -> robot joint index
  if (!ConnectRobot(options, &link, &order, &result)) return result;

  SessionInfo info = options.info;
  info.joint_names = options.joint_names;
  info.settings["mode"] = "step_and_shoot";
  info.settings["shots_per_pose"] = std::to_string(options.shots);
  info.settings["robot"] = result.robot_name;
  SessionRecorder recorder(options.recorder);
  const Status opened = recorder.Open(options.out, info);
  if (!opened.ok()) {
    link.WriteLine("ERROR cannot create the session");
    SetOutcome(&result, StepAndShootResult::kFailure, opened.ToString());
    return result;
  }
  result.session_created = true;
  link.WriteLine("OK kincal 1");

  const auto start = std::chrono::steady_clock::now();
  PoseLoop loop =
      RecordPoses(grabber, live, options, order, &link, &recorder, &result);
  link.Close();
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  std::string& failure = loop.failure;
  auto write = [&](const std::string& name, const std::string& text) {
    try {
      WriteFileAtomic(options.out + "/" + name, text);
    } catch (const std::exception& e) {
      if (failure.empty()) failure = e.what();
    }
  };
  write("observations.csv", loop.obs_csv);
  if (result.joint_stream) write("joints.csv", loop.stream_csv);
  SessionSummary summary;
  summary.complete = failure.empty() && loop.bad_input.empty();
  summary.stop_reason = !failure.empty()          ? failure
                        : !loop.bad_input.empty() ? loop.bad_input
                                                  : result.stop_reason;
  summary.dropped = grabber->dropped();
  summary.seconds = result.seconds;
  const Status fin = recorder.Finalize(summary);
  if (!fin.ok() && failure.empty()) failure = "finalize: " + fin.ToString();
  result.frames = recorder.frames();
  result.stop_reason = summary.stop_reason;
  result.complete = failure.empty() && loop.bad_input.empty();
  const std::string kept = " (the " + std::to_string(result.frames) +
                           " poses recorded so far are kept in " + options.out +
                           ")";
  if (!loop.bad_input.empty()) {
    SetOutcome(&result, StepAndShootResult::kBadInput, loop.bad_input + kept);
  } else if (!failure.empty()) {
    SetOutcome(&result, StepAndShootResult::kFailure, failure + kept);
  }
  return result;
}

}  // namespace kincal::capture
