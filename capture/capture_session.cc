#include "capture/capture_session.h"

#include <dirent.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "capture/async_recorder.h"
#include "capture/frame_grabber.h"
#include "capture/frame_source.h"
#include "capture/joint_log.h"
#include "capture/joint_stream.h"
#include "capture/recorder.h"
#include "capture/robot_link.h"
#include "data/error.h"
#include "data/observation_checks.h"
#include "data/progress.h"
#include "data/robot.h"
#include "data/session.h"
#include "data/warnings.h"

namespace kincal::capture {
namespace {

// True when `dir` does not exist or is an empty folder.
bool IsAbsentOrEmptyDir(const std::string& dir) {
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) return errno == ENOENT;
  bool empty = true;
  while (dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name != "." && name != "..") {
      empty = false;
      break;
    }
  }
  ::closedir(d);
  return empty;
}

// The checked inputs: every camera's source (not yet open, in rig order)
// and the joint log.
struct Inputs {
  std::vector<std::unique_ptr<FrameSource>> sources;
  std::optional<JointLog> joint_log;
  bool live = false;
  Warnings warnings;

  std::vector<FrameSource*> Sources() const {
    std::vector<FrameSource*> out;
    for (const auto& s : sources) out.push_back(s.get());
    return out;
  }
};

// The log's readings against the robot file: a reading outside its joint's
// limits is refused (file:line, joint), readings that look like radians
// warned about (data/observation_checks.h).
void CheckLogAgainstRobot(const Robot& robot, const JointLog& log,
                          const std::string& robot_file, Warnings* warnings) {
  std::vector<int> column(robot.joints.size(), -1);
  for (size_t k = 0; k < robot.joints.size(); ++k) {
    for (size_t c = 0; c < log.names.size(); ++c) {
      if (log.names[c] == robot.joints[k].name) column[k] = static_cast<int>(c);
    }
  }
  std::vector<std::vector<double>> rows;
  rows.reserve(log.q.size());
  for (size_t r = 0; r < log.q.size(); ++r) {
    std::vector<double> q(robot.joints.size(), 0.0);
    for (size_t k = 0; k < robot.joints.size(); ++k) {
      if (column[k] < 0) continue;
      q[k] = log.q[r][column[k]];
      CheckReadingWithinLimits(robot.joints[k], q[k], log.source,
                               r < log.lines.size() ? log.lines[r] : 0,
                               robot_file);
    }
    rows.push_back(q);
  }
  CheckJointUnits(robot, rows, log.source, warnings);
}

// The cameras: names that can name a folder, each once; sources that parse,
// none given twice; all cameras or all recordings. Fills in->sources.
void CheckCameras(const CaptureOptions& options, Inputs* in) {
  const std::vector<CaptureCamera>& cams = options.cameras;
  std::vector<SourceUri> uris;
  for (size_t k = 0; k < cams.size(); ++k) {
    CheckSessionCameraName(cams[k].name, "capture: a camera name");
    uris.push_back(ParseSourceUri(cams[k].uri));
    for (size_t j = 0; j < k; ++j) {
      Require(cams[j].name != cams[k].name,
              "capture: camera '" + cams[k].name +
                  "' is given twice; every camera needs its own name");
      Require(uris[j].scheme + ":" + uris[j].path !=
                  uris[k].scheme + ":" + uris[k].path,
              "capture: cameras '" + cams[j].name + "' and '" + cams[k].name +
                  "' name the same source '" + uris[k].path + "'");
    }
  }
  for (const SourceUri& uri : uris) in->sources.push_back(MakeFrameSource(uri));
  for (size_t k = 1; k < cams.size(); ++k) {
    Require(in->sources[k]->IsLive() == in->sources[0]->IsLive(),
            "capture: cannot pair a camera with a recording (" + cams[0].name +
                ": " + cams[0].uri + ", " + cams[k].name + ": " + cams[k].uri +
                "): use only cameras or only recordings");
  }
  in->live = in->sources[0]->IsLive();
}

// Everything the user typed is checked before a camera or file is touched.
Inputs CheckInputs(const CaptureOptions& options) {
  Require(!options.cameras.empty() && !options.out.empty(),
          "capture: cameras (--camera NAME=URI, or --left and --right) and "
          "--out are required (or use --list)");
  Inputs in;
  in.warnings = Warnings(&std::cerr);
  CheckCameras(options, &in);
  if (!options.joints.empty()) {
    std::vector<std::string> names;
    Robot robot;
    if (!options.robot.empty()) {
      robot = ReadRobotYaml(options.robot);
      names = robot.JointNames();
    }
    in.joint_log =
        ReadJointLog(options.joints, options.robot.empty() ? nullptr : &names);
    if (!options.robot.empty()) {
      CheckLogAgainstRobot(robot, *in.joint_log, options.robot, &in.warnings);
    }
  } else {
    Require((options.robot.empty() || !options.robot_listen.empty()) &&
                std::isnan(options.joints_offset),
            "capture: --robot goes with --joints or --robot-listen, "
            "--joints-offset with --joints");
  }
  Require(IsAbsentOrEmptyDir(options.out),
          "capture: --out " + options.out +
              " exists and is not empty; kincal never overwrites a session, "
              "choose a new folder");
  return in;
}

// Opens the cameras. A missing replay file is bad input (InputError); a
// camera that cannot be opened is the returned failure.
Status OpenGrabber(FrameGrabber* grabber, bool live) {
  const Status s = grabber->Open();
  if (!s.ok() && !live && s.kind() == Status::Kind::kNotFound) {
    throw InputError("capture: " + s.message());
  }
  return s;
}

// What session.yaml records about the cameras and their pairing.
SessionInfo DescribeCameras(const CaptureOptions& options, const Inputs& in,
                            const FrameGrabber& grabber, double tolerance_s) {
  SessionInfo info;
  for (size_t k = 0; k < options.cameras.size(); ++k) {
    info.cameras.push_back({options.cameras[k].name, options.cameras[k].uri,
                            in.sources[k]->Describe(),
                            in.sources[k]->mosaic()});
  }
  info.live = in.live;
  info.pairing = PairingName(grabber.pairing());
  info.tolerance_s =
      grabber.pairing() == FrameGrabber::Pairing::kLockStep ? 0.0 : tolerance_s;
  info.time_base = TimeBaseName(in.sources[0]->time_base());
  return info;
}

CaptureResult Failed(CaptureResult result, CaptureResult::Outcome outcome,
                     std::string message) {
  result.outcome = outcome;
  result.message = std::move(message);
  return result;
}

// Step and shoot with a live robot link (capture/step_and_shoot.h).
CaptureResult RunStepAndShootMode(const CaptureOptions& options, Inputs* in) {
  Require(!options.robot.empty(),
          "capture: --robot-listen needs --robot robot.yaml (joint names)");
  Require(options.joints.empty(),
          "capture: --joints and --robot-listen exclude each other");
  StepAndShootOptions step;
  step.joint_names = ReadRobotYaml(options.robot).JointNames();
  step.robot_file = options.robot;
  step.listen = options.robot_listen;
  step.shots = options.shots;
  step.timeout_s = options.robot_timeout;
  step.out = options.out;
  step.recorder.png_compression = options.png_compression;
  step.announce = options.announce;
  step.interrupted = options.interrupted;
  FrameGrabberOptions grab_options;
  grab_options.tolerance_s = options.tolerance_ms * 1e-3;
  FrameGrabber grabber(in->Sources(), grab_options);
  CaptureResult result;
  result.step_and_shoot = true;
  const Status opened = OpenGrabber(&grabber, in->live);
  if (!opened.ok()) {
    return Failed(result, CaptureResult::kFailure,
                  "capture: " + opened.ToString());
  }
  step.info = DescribeCameras(options, *in, grabber, grab_options.tolerance_s);
  step.info.settings["png_compression"] =
      std::to_string(options.png_compression);
  if (options.before_recording) options.before_recording();
  result.step = RunStepAndShoot(&grabber, in->live, step);
  for (size_t k = 0; k < step.info.cameras.size(); ++k) {
    const SessionCamera& c = step.info.cameras[k];
    result.cameras.push_back(
        {c.name, c.uri, c.description, grabber.dropped(k), c.mosaic});
  }
  grabber.Close();
  if (result.step.outcome == StepAndShootResult::kBadInput) {
    return Failed(result, CaptureResult::kBadInput,
                  "capture: " + result.step.message);
  }
  if (result.step.outcome == StepAndShootResult::kFailure) {
    return Failed(result, CaptureResult::kFailure,
                  "capture: " + result.step.message);
  }
  return result;
}

// The robot connects and says HELLO before anything is written (an unknown
// joint is bad input with nothing on disk). Returns the receiver, or null
// with the failure in *failure.
std::unique_ptr<JointStreamReceiver> OpenJointStream(
    const CaptureOptions& options, RobotLink* link, std::string* failure) {
  const std::vector<std::string> names =
      ReadRobotYaml(options.robot).JointNames();
  Status s = link->Listen(options.robot_listen);
  if (s.kind() == Status::Kind::kUnsupported) {
    throw InputError("capture: --robot-listen: " + s.message());
  }
  if (options.announce && s.ok()) {
    std::cerr << "kincal capture: waiting for the robot on port "
              << link->port() << "\n";
  }
  if (s.ok()) s = link->Accept(options.robot_timeout);
  std::vector<int> order;
  std::string robot_name;
  if (s.ok()) {
    s = ReceiveHello(link, names, options.robot, options.robot_timeout, &order,
                     &robot_name);
  }
  if (s.kind() == Status::Kind::kUnsupported) {
    throw InputError("capture: " + s.message() + " (nothing written)");
  }
  if (!s.ok()) {
    *failure = "capture: " + s.ToString() + " (nothing written)";
    return nullptr;
  }
  return std::make_unique<JointStreamReceiver>(link, order, names);
}

// Image motion (for the joint log's clock offset): mean absolute change of
// the image, about 160 px wide, since the previous call's.
double ImageMotion(const cv::Mat& image, cv::Mat* previous_small) {
  cv::Mat small;
  const double scale = std::min(1.0, 160.0 / std::max(1, image.cols));
  cv::resize(image, small, cv::Size(), scale, scale, cv::INTER_AREA);
  if (small.channels() == 3) cv::cvtColor(small, small, cv::COLOR_BGR2GRAY);
  double motion = 0;
  if (!previous_small->empty()) {
    cv::Mat diff;
    cv::absdiff(small, *previous_small, diff);
    motion = cv::mean(diff)[0];
  }
  *previous_small = small;
  return motion;
}

// What the recording loop saw.
struct Recording {
  // The reference (first) camera's timestamps of the accepted sets.
  std::vector<double> frame_times;
  std::vector<double> image_motion;  // per accepted set (joint log only)
  std::string stop_reason;
  std::string failure;  // camera or writer failure, else empty
  int64_t transient_failures = 0;
  double seconds = 0;
};

// Grabs frame sets and hands them to the writers until a limit, the end of
// the recordings, the robot's BYE, Ctrl-C or a failure. Never waits for the
// disk: a full queue drops the set (counted by the writer).
Recording RecordSets(const CaptureOptions& options, bool live,
                     bool track_motion, FrameGrabber* grabber,
                     AsyncRecorder* writer, const JointStreamReceiver* stream) {
  Recording rec;
  int64_t accepted = 0;
  cv::Mat previous_small;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  int consecutive_failures = 0;
  FrameSet set;
  const std::string noun = FrameSetNoun(grabber->cameras());
  // Progress on a terminal: sets recorded (of --frames when given), drops.
  Progress progress("kincal capture", !options.announce);
  double last_progress_s = -1;
  for (;;) {
    if (progress.enabled() && elapsed() - last_progress_s >= 0.5) {
      last_progress_s = elapsed();
      progress.Stage(
          std::to_string(accepted) +
          (options.frames > 0 ? "/" + std::to_string(options.frames) : "") +
          " " + noun + " recorded, " + std::to_string(writer->dropped_sets()) +
          " dropped, " + std::to_string(static_cast<int>(last_progress_s)) +
          " s");
    }
    if (options.frames > 0 && accepted >= options.frames) {
      rec.stop_reason = "frames";
      break;
    }
    if (options.seconds > 0 && elapsed() >= options.seconds) {
      rec.stop_reason = "seconds";
      break;
    }
    if (stream != nullptr && stream->finished()) {
      rec.stop_reason = "robot_bye";
      break;
    }
    if (options.interrupted != nullptr && options.interrupted->load()) {
      rec.stop_reason = "interrupted";
      break;
    }
    const Status s = grabber->Grab(&set);
    if (s.kind() == Status::Kind::kEndOfStream) {
      rec.stop_reason = "end_of_stream";
      break;
    }
    if (!s.ok()) {
      // A live camera may time out or deliver a corrupt frame now and then.
      const bool transient = live && (s.kind() == Status::Kind::kTimeout ||
                                      s.kind() == Status::Kind::kIoError);
      if (transient && ++consecutive_failures <= options.max_failures) {
        ++rec.transient_failures;
        std::cerr << "kincal capture: warning: " << s.ToString() << "\n";
        continue;
      }
      rec.failure = "grab: " + s.ToString();
      break;
    }
    consecutive_failures = 0;
    const double t_reference = set.frames[0].timestamp_s;
    const double motion =
        track_motion ? ImageMotion(set.frames[0].image, &previous_small) : 0.0;
    if (writer->Submit(std::move(set))) {
      ++accepted;
      rec.frame_times.push_back(t_reference);
      rec.image_motion.push_back(motion);
    } else if (writer->failed()) {
      break;
    }
    set = FrameSet();
  }
  rec.seconds = elapsed();
  progress.Done();
  return rec;
}

// Merges a controller joint log by time into the recorded frames. InputError
// when it cannot be merged.
CaptureJoints MergeLogReadings(const CaptureOptions& options,
                               const JointLog& log, Recording* rec,
                               SessionRecorder* recorder) {
  rec->frame_times.resize(recorder->frames());
  rec->image_motion.resize(recorder->frames());
  std::vector<double>& motion = rec->image_motion;
  if (!motion.empty()) motion[0] = motion.size() > 1 ? motion[1] : 0.0;
  JointMergeOptions merge_options;
  if (!std::isnan(options.joints_offset)) {
    merge_options.offset_s = options.joints_offset;
  }
  merge_options.max_speed = options.max_joint_speed;
  const JointMerge merge =
      MergeJointLog(log, rec->frame_times, motion, merge_options);
  const Status s = recorder->SetJointColumns(merge.names, merge.joints);
  if (!s.ok()) throw InputError("capture: " + s.message());
  char offset[64];
  std::snprintf(offset, sizeof(offset), "%.6f", merge.offset_s);
  recorder->SetSetting("joints_log", options.joints);
  recorder->SetSetting("joints_offset_s", offset);
  recorder->SetSetting("joints_offset",
                       merge.estimated ? "estimated" : "given");
  recorder->SetSetting("max_joint_speed",
                       std::to_string(options.max_joint_speed));
  CaptureJoints joints;
  joints.log = options.joints;
  joints.offset_s = merge.offset_s;
  joints.offset_estimated = merge.estimated;
  joints.agreement = merge.agreement;
  joints.stops_matched = merge.stops_matched;
  joints.frames_with_reading = merge.with_reading;
  joints.frames_too_fast = merge.too_fast;
  return joints;
}

// The live stream: readings on the controller clock, put on the host clock
// by the fastest sample; frames outside it get no reading.
CaptureJoints MergeStreamReadings(const CaptureOptions& options,
                                  const JointStreamReceiver& stream,
                                  Recording* rec, SessionRecorder* recorder) {
  rec->frame_times.resize(recorder->frames());
  const JointLog log = stream.Log();
  JointMergeOptions merge_options;
  merge_options.offset_s = stream.OffsetToHost();
  merge_options.max_speed = options.max_joint_speed;
  merge_options.uncovered_ok = true;
  const JointMerge merge =
      MergeJointLog(log, rec->frame_times, {}, merge_options);
  const Status s = recorder->SetJointColumns(merge.names, merge.joints);
  if (!s.ok()) throw InputError("capture: " + s.message());
  recorder->SetSetting("joints_offset_s", std::to_string(merge.offset_s));
  recorder->SetSetting("joints_offset", "stream (fastest sample)");
  CaptureJoints joints;
  joints.from_stream = true;
  joints.samples = static_cast<int64_t>(log.t.size());
  joints.offset_s = merge.offset_s;
  joints.frames_with_reading = merge.with_reading;
  joints.frames_too_fast = merge.too_fast;
  return joints;
}

// The settings session.yaml records for a continuous recording.
void RecordSettings(const CaptureOptions& options, bool stream,
                    SessionInfo* info) {
  if (stream) info->settings["mode"] = "joint_stream";
  if (options.frames > 0) {
    info->settings["frames"] = std::to_string(options.frames);
  }
  if (options.seconds > 0) {
    info->settings["seconds"] = std::to_string(options.seconds);
  }
  info->settings["png_compression"] = std::to_string(options.png_compression);
  info->settings["queue_pairs"] = std::to_string(options.queue_sets);
  info->settings["writers"] = std::to_string(options.writers);
}

// What session.yaml records about how the recording ended.
SessionSummary Summarize(const Recording& rec, const std::string& failure,
                         const std::string& stream_bad_input,
                         const FrameGrabber& grabber,
                         const AsyncRecorder& writer) {
  SessionSummary summary;
  summary.complete = failure.empty() && stream_bad_input.empty();
  summary.stop_reason = !failure.empty()            ? failure
                        : !stream_bad_input.empty() ? stream_bad_input
                                                    : rec.stop_reason;
  summary.dropped = grabber.dropped();
  summary.dropped_sets = writer.dropped_sets();
  summary.length_mismatch = grabber.length_mismatch();
  summary.seconds = rec.seconds;
  return summary;
}

// The figures of a finished recording, into `result`.
void DescribeRecording(const SessionInfo& info, const FrameGrabber& grabber,
                       const AsyncRecorder& writer,
                       const SessionRecorder& recorder, const Recording& rec,
                       const SessionSummary& summary, CaptureResult* result) {
  result->recorded = true;
  result->frames = recorder.frames();
  result->seconds = rec.seconds;
  result->bytes = recorder.bytes_written();
  for (size_t k = 0; k < info.cameras.size(); ++k) {
    const SessionCamera& c = info.cameras[k];
    result->cameras.push_back(
        {c.name, c.uri, c.description, grabber.dropped(k), c.mosaic});
  }
  result->pairing = info.pairing;
  result->dropped_sets = writer.dropped_sets();
  result->max_queue_depth = writer.max_queue_depth();
  result->fast_sets = writer.fast_sets();
  result->length_mismatch = grabber.length_mismatch();
  result->transient_failures = rec.transient_failures;
  result->stop_reason = summary.stop_reason;
}

// The outcome of a finished recording: bad input from the stream, then a
// joint log that could not be merged, then a camera, disk or robot failure.
CaptureResult Conclude(CaptureResult result, const std::string& out,
                       const std::string& stream_bad_input,
                       const std::string& joint_error,
                       const std::string& failure) {
  const std::string frames =
      std::to_string(result.frames) + " " + FrameSetNoun(result.cameras.size());
  if (!stream_bad_input.empty()) {
    return Failed(result, CaptureResult::kBadInput,
                  "capture: " + stream_bad_input + " (the " + frames +
                      " recorded are kept in " + out + ")");
  }
  if (!joint_error.empty()) {
    return Failed(result, CaptureResult::kBadInput,
                  joint_error + " (the " + frames + " recorded are kept in " +
                      out + ", without joint readings)");
  }
  if (!failure.empty()) {
    return Failed(result, CaptureResult::kFailure,
                  "capture: " + failure + " (the " + frames +
                      " recorded so far are kept in " + out + ")");
  }
  return result;
}

}  // namespace

CaptureResult RunCaptureSession(const CaptureOptions& options) {
  Inputs in = CheckInputs(options);
  const bool live = in.live;
  if (!options.robot_listen.empty() && !options.stream) {
    return RunStepAndShootMode(options, &in);
  }
  Require(!options.stream ||
              (!options.robot_listen.empty() && !options.robot.empty() &&
               options.joints.empty() && live),
          "capture: --stream needs --robot-listen, --robot, live cameras (the "
          "stream is put on the host clock) and no --joints");

  CaptureResult result;
  result.warnings = in.warnings.list();
  FrameGrabberOptions grab_options;
  grab_options.tolerance_s = options.tolerance_ms * 1e-3;
  FrameGrabber grabber(in.Sources(), grab_options);
  const Status opened = OpenGrabber(&grabber, live);
  if (!opened.ok()) {
    return Failed(result, CaptureResult::kFailure,
                  "capture: " + opened.ToString());
  }
  RobotLink link;
  std::unique_ptr<JointStreamReceiver> stream;
  if (options.stream) {
    std::string failure;
    stream = OpenJointStream(options, &link, &failure);
    if (!stream) return Failed(result, CaptureResult::kFailure, failure);
  }

  SessionInfo info =
      DescribeCameras(options, in, grabber, grab_options.tolerance_s);
  RecordSettings(options, stream != nullptr, &info);
  SessionRecorder::Options recorder_options;
  recorder_options.png_compression = options.png_compression;
  SessionRecorder recorder(recorder_options);
  const Status created = recorder.Open(options.out, info);
  if (!created.ok()) {
    return Failed(result, CaptureResult::kFailure,
                  "capture: " + created.ToString());
  }
  if (live && options.frames == 0 && options.seconds == 0 && options.announce) {
    std::cerr << "kincal capture: recording until Ctrl-C"
              << (stream ? " or the robot's BYE" : "") << "\n";
  }
  if (stream) {
    link.WriteLine("OK kincal 1");
    stream->Start();
  }

  AsyncRecorderOptions async_options;
  async_options.queue_sets = options.queue_sets;
  async_options.writer_threads = options.writers;
  async_options.drop_when_full = live;  // a recording can wait
  AsyncRecorder writer(&recorder, async_options);
  if (options.before_recording) options.before_recording();
  Recording rec = RecordSets(options, live, in.joint_log.has_value(), &grabber,
                             &writer, stream.get());
  grabber.Close();
  const Status written = writer.Stop();  // drains the queue
  std::string failure = rec.failure;
  if (!written.ok() && failure.empty())
    failure = "write: " + written.ToString();
  std::string stream_bad_input;
  if (stream) {
    stream->Stop();
    link.Close();
    const Status st = stream->status();
    if (st.kind() == Status::Kind::kUnsupported) {
      stream_bad_input = st.message();
    } else if (!st.ok() && failure.empty()) {
      failure = st.message();
    }
  }

  const SessionSummary summary =
      Summarize(rec, failure, stream_bad_input, grabber, writer);
  // Joint readings are merged before finalizing. A log that cannot be
  // merged is bad input: the session is kept without joint columns.
  std::string joint_error;
  if (in.joint_log && recorder.frames() > 0) {
    try {
      result.joints = MergeLogReadings(options, *in.joint_log, &rec, &recorder);
      result.has_joints = true;
    } catch (const InputError& e) {
      joint_error = e.what();
    }
  }
  if (stream && recorder.frames() > 0) {
    try {
      result.joints = MergeStreamReadings(options, *stream, &rec, &recorder);
      result.has_joints = true;
    } catch (const InputError& e) {
      if (failure.empty() && stream_bad_input.empty()) joint_error = e.what();
    }
  }
  const Status finalized = recorder.Finalize(summary);
  if (!finalized.ok() && failure.empty()) {
    failure = "finalize: " + finalized.ToString();
  }

  DescribeRecording(info, grabber, writer, recorder, rec, summary, &result);
  result.complete = failure.empty();
  return Conclude(result, options.out, stream_bad_input, joint_error, failure);
}

}  // namespace kincal::capture
