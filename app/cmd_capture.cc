// kincal capture: record a stereo session (left/*.png, right/*.png,
// frames.csv, session.yaml) from two cameras or two recordings, in the layout
// `kincal track` reads directly; `kincal capture --list` lists cameras.

#include <dirent.h>
#include <signal.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "app/command.h"
#include "app/front_end.h"
#include "capture/async_recorder.h"
#include "capture/frame_source.h"
#include "capture/joint_log.h"
#include "capture/joint_stream.h"
#include "capture/recorder.h"
#include "capture/robot_link.h"
#include "capture/step_and_shoot.h"
#include "capture/stereo_grabber.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/progress.h"
#include "data/provenance.h"
#include "data/robot.h"

namespace kincal::app {
namespace {

using capture::Status;

struct CaptureArgs {
  std::string left, right, out;
  int64_t frames = 0;
  double seconds = 0;
  double tolerance_ms = 10;
  int png_compression = 1;
  int max_failures = 3;
  int queue_pairs = 32;
  std::string joints, robot;
  double joints_offset = NAN;  // NaN: estimate
  double max_joint_speed = 1.0;
  std::string robot_listen;  // step-and-shoot
  int shots = 5;
  double robot_timeout = 600;
  bool stream = false;  // --robot-listen with continuous recording
  int writers = 2;
  bool list = false;
  bool json = false;
};

std::atomic<bool> g_interrupted{false};
extern "C" void OnInterrupt(int) { g_interrupted = true; }

// Installs a Ctrl-C handler for the lifetime of the object, so an
// interrupted recording is finalized instead of killed.
class InterruptGuard {
 public:
  InterruptGuard() {
    g_interrupted = false;
    struct sigaction sa {};
    sa.sa_handler = OnInterrupt;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~InterruptGuard() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

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

nlohmann::json CamerasJson(const std::vector<capture::CameraInfo>& cams) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : cams) {
    out.push_back({{"uri", c.uri},
                   {"description", c.description},
                   {"formats", c.formats}});
  }
  return out;
}

int RunList(const CaptureArgs& args) {
  const auto v4l2 = capture::ListV4l2Devices();
  std::vector<capture::CameraInfo> aravis;
  const Status aravis_status = capture::ListAravisCameras(&aravis);
  if (args.json) {
    nlohmann::json j;
    j["v4l2"] = CamerasJson(v4l2);
    j["aravis"] = CamerasJson(aravis);
    j["aravis_available"] = capture::HaveAravis();
    j["libv4l2"] = capture::HaveLibV4l2();
    if (!aravis_status.ok()) j["aravis_status"] = aravis_status.ToString();
    PrintJson(j);
    return 0;
  }
  std::cout << "V4L2 devices" << (capture::HaveLibV4l2() ? " (libv4l2)" : "")
            << ":\n";
  if (v4l2.empty()) std::cout << "  (none)\n";
  for (const auto& c : v4l2) {
    std::cout << "  " << c.uri << "  " << c.description << "\n";
    for (const auto& f : c.formats) std::cout << "      " << f << "\n";
  }
  std::cout << "Aravis cameras (GigE / USB3 Vision):\n";
  if (!aravis_status.ok()) {
    std::cout << "  (" << aravis_status.message() << ")\n";
  } else if (aravis.empty()) {
    std::cout << "  (none)\n";
  }
  for (const auto& c : aravis) {
    std::cout << "  " << c.uri << "  " << c.description << "\n";
  }
  return 0;
}

// Opens the pair. A missing replay file is bad input (InputError); a camera
// that cannot be opened is a failure: message on stderr, false.
bool OpenGrabber(capture::StereoGrabber* grabber, bool live) {
  const Status s = grabber->Open();
  if (s.ok()) return true;
  if (!live && s.kind() == Status::Kind::kNotFound) {
    throw InputError("capture: " + s.message());
  }
  std::cerr << "kincal: failure: capture: " << s.ToString() << std::endl;
  return false;
}

// What session.yaml records about the cameras and their pairing.
capture::SessionInfo DescribeCameras(const CaptureArgs& args,
                                     const capture::FrameSource& left,
                                     const capture::FrameSource& right,
                                     const capture::StereoGrabber& grabber,
                                     double tolerance_s, bool live) {
  capture::SessionInfo info;
  info.left_uri = args.left;
  info.right_uri = args.right;
  info.left_description = left.Describe();
  info.right_description = right.Describe();
  info.live = live;
  info.pairing = capture::PairingName(grabber.pairing());
  info.tolerance_s =
      grabber.pairing() == capture::StereoGrabber::Pairing::kLockStep
          ? 0.0
          : tolerance_s;
  info.time_base = capture::TimeBaseName(left.time_base());
  return info;
}

// Step and shoot with a live robot link (capture/step_and_shoot.h).
int RunStepAndShoot(const CaptureArgs& args, capture::FrameSource* left,
                    capture::FrameSource* right, bool live) {
  Require(!args.robot.empty(),
          "capture: --robot-listen needs --robot robot.yaml (joint names)");
  Require(args.joints.empty(),
          "capture: --joints and --robot-listen exclude each other");
  capture::StepAndShootOptions options;
  options.joint_names = ReadRobotYaml(args.robot).JointNames();
  options.robot_file = args.robot;
  options.listen = args.robot_listen;
  options.shots = args.shots;
  options.timeout_s = args.robot_timeout;
  options.out = args.out;
  options.recorder.png_compression = args.png_compression;
  options.announce = !args.json;
  options.interrupted = &g_interrupted;
  capture::StereoGrabberOptions grab_options;
  grab_options.tolerance_s = args.tolerance_ms * 1e-3;
  capture::StereoGrabber grabber(left, right, grab_options);
  if (!OpenGrabber(&grabber, live)) return 1;
  capture::SessionInfo& info = options.info;
  info = DescribeCameras(args, *left, *right, grabber, grab_options.tolerance_s,
                         live);
  info.settings["png_compression"] = std::to_string(args.png_compression);

  InterruptGuard guard;
  const capture::StepAndShootResult r =
      capture::RunStepAndShoot(&grabber, live, options);
  grabber.Close();
  if (r.session_created) {
    if (args.json) {
      nlohmann::json j;
      j["out"] = args.out;
      j["mode"] = "step_and_shoot";
      j["frames"] = r.frames;
      j["poses"] = r.poses;
      j["shots_per_pose"] = args.shots;
      j["robot"] = r.robot_name;
      j["joint_stream"] = r.joint_stream;
      j["seconds"] = r.seconds;
      j["stop_reason"] = r.stop_reason;
      j["complete"] = r.complete;
      PrintJson(j);
    } else {
      std::printf(
          "recorded %ld settled poses (%d pairs averaged each) to %s; "
          "stopped: %s\n",
          r.poses, args.shots, args.out.c_str(), r.stop_reason.c_str());
    }
  }
  if (r.outcome == capture::StepAndShootResult::kBadInput) {
    throw InputError("capture: " + r.message);
  }
  if (r.outcome == capture::StepAndShootResult::kFailure) {
    std::cerr << "kincal: failure: capture: " << r.message << std::endl;
    return 1;
  }
  return 0;
}

int RunCapture(const CaptureArgs& args) {
  if (args.list) return RunList(args);
  Require(!args.left.empty() && !args.right.empty() && !args.out.empty(),
          "capture: --left, --right and --out are required (or use --list)");
  // Everything the user typed is checked before a camera or file is touched.
  const capture::SourceUri left_uri = capture::ParseSourceUri(args.left);
  const capture::SourceUri right_uri = capture::ParseSourceUri(args.right);
  Require(left_uri.scheme + ":" + left_uri.path !=
              right_uri.scheme + ":" + right_uri.path,
          "capture: --left and --right name the same source '" + left_uri.path +
              "'");
  auto left = capture::MakeFrameSource(left_uri);
  auto right = capture::MakeFrameSource(right_uri);
  Require(left->IsLive() == right->IsLive(),
          "capture: cannot pair a camera with a recording (--left " +
              args.left + ", --right " + args.right +
              "): use two cameras or two recordings");
  std::optional<capture::JointLog> joint_log;
  if (!args.joints.empty()) {
    std::vector<std::string> names;
    if (!args.robot.empty()) names = ReadRobotYaml(args.robot).JointNames();
    joint_log = capture::ReadJointLog(args.joints,
                                      args.robot.empty() ? nullptr : &names);
  } else {
    Require((args.robot.empty() || !args.robot_listen.empty()) &&
                std::isnan(args.joints_offset),
            "capture: --robot goes with --joints or --robot-listen, "
            "--joints-offset with --joints");
  }
  Require(IsAbsentOrEmptyDir(args.out),
          "capture: --out " + args.out +
              " exists and is not empty; kincal never overwrites a session, "
              "choose a new folder");
  const bool live = left->IsLive();
  if (!args.robot_listen.empty() && !args.stream) {
    return RunStepAndShoot(args, left.get(), right.get(), live);
  }
  Require(!args.stream || (!args.robot_listen.empty() && !args.robot.empty() &&
                           args.joints.empty() && live),
          "capture: --stream needs --robot-listen, --robot, live cameras (the "
          "stream is put on the host clock) and no --joints");

  capture::StereoGrabberOptions options;
  options.tolerance_s = args.tolerance_ms * 1e-3;
  capture::StereoGrabber grabber(left.get(), right.get(), options);
  if (!OpenGrabber(&grabber, live)) return 1;
  Status s;

  // Live joint stream: the robot connects and says HELLO before anything
  // is written (an unknown joint is bad input with nothing on disk).
  capture::RobotLink link;
  std::unique_ptr<capture::JointStreamReceiver> stream;
  if (args.stream) {
    const std::vector<std::string> names =
        ReadRobotYaml(args.robot).JointNames();
    s = link.Listen(args.robot_listen);
    if (s.kind() == Status::Kind::kUnsupported) {
      throw InputError("capture: --robot-listen: " + s.message());
    }
    if (!args.json && s.ok()) {
      std::cerr << "kincal capture: waiting for the robot on port "
                << link.port() << "\n";
    }
    if (s.ok()) s = link.Accept(args.robot_timeout);
    std::vector<int> order;
    std::string robot_name;
    if (s.ok()) {
      s = capture::ReceiveHello(&link, names, args.robot, args.robot_timeout,
                                &order, &robot_name);
    }
    if (s.kind() == Status::Kind::kUnsupported) {
      throw InputError("capture: " + s.message() + " (nothing written)");
    }
    if (!s.ok()) {
      std::cerr << "kincal: failure: capture: " << s.ToString()
                << " (nothing written)" << std::endl;
      return 1;
    }
    stream =
        std::make_unique<capture::JointStreamReceiver>(&link, order, names);
  }

  capture::SessionInfo info =
      DescribeCameras(args, *left, *right, grabber, options.tolerance_s, live);
  if (stream) info.settings["mode"] = "joint_stream";
  if (args.frames > 0) info.settings["frames"] = std::to_string(args.frames);
  if (args.seconds > 0) info.settings["seconds"] = std::to_string(args.seconds);
  info.settings["png_compression"] = std::to_string(args.png_compression);
  info.settings["queue_pairs"] = std::to_string(args.queue_pairs);
  info.settings["writers"] = std::to_string(args.writers);

  capture::SessionRecorder::Options rec_options;
  rec_options.png_compression = args.png_compression;
  capture::SessionRecorder recorder(rec_options);
  s = recorder.Open(args.out, info);
  if (!s.ok()) {
    std::cerr << "kincal: failure: capture: " << s.ToString() << std::endl;
    return 1;
  }
  if (live && args.frames == 0 && args.seconds == 0 && !args.json) {
    std::cerr << "kincal capture: recording until Ctrl-C"
              << (stream ? " or the robot's BYE" : "") << "\n";
  }
  if (stream) {
    link.WriteLine("OK kincal 1");
    stream->Start();
  }

  capture::AsyncRecorderOptions async_options;
  async_options.queue_pairs = args.queue_pairs;
  async_options.writer_threads = args.writers;
  async_options.drop_when_full = live;  // a recording can wait
  capture::AsyncRecorder writer(&recorder, async_options);
  int64_t accepted = 0;
  std::vector<double> frame_times, image_motion;
  cv::Mat previous_small;

  InterruptGuard guard;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  std::string stop_reason;
  std::string failure;
  int consecutive_failures = 0;
  int64_t transient_failures = 0;
  capture::StereoFrame pair;
  // Progress on a terminal: pairs recorded (of --frames when given), drops.
  Progress progress("kincal capture", args.json);
  double last_progress_s = -1;
  for (;;) {
    if (progress.enabled() && elapsed() - last_progress_s >= 0.5) {
      last_progress_s = elapsed();
      progress.Stage(
          std::to_string(accepted) +
          (args.frames > 0 ? "/" + std::to_string(args.frames) : "") +
          " pairs recorded, " + std::to_string(writer.dropped_pairs()) +
          " dropped, " + std::to_string(static_cast<int>(last_progress_s)) +
          " s");
    }
    if (args.frames > 0 && accepted >= args.frames) {
      stop_reason = "frames";
      break;
    }
    if (args.seconds > 0 && elapsed() >= args.seconds) {
      stop_reason = "seconds";
      break;
    }
    if (stream && stream->finished()) {
      stop_reason = "robot_bye";
      break;
    }
    if (g_interrupted) {
      stop_reason = "interrupted";
      break;
    }
    s = grabber.Grab(&pair);
    if (s.kind() == Status::Kind::kEndOfStream) {
      stop_reason = "end_of_stream";
      break;
    }
    if (!s.ok()) {
      // A live camera may time out or deliver a corrupt frame now and then.
      const bool transient = live && (s.kind() == Status::Kind::kTimeout ||
                                      s.kind() == Status::Kind::kIoError);
      if (transient && ++consecutive_failures <= args.max_failures) {
        ++transient_failures;
        std::cerr << "kincal capture: warning: " << s.ToString() << "\n";
        continue;
      }
      failure = "grab: " + s.ToString();
      break;
    }
    consecutive_failures = 0;
    // Image motion (for the joint log's clock offset): mean absolute
    // change of the left image, about 160 px wide, since the previous pair.
    double motion = 0, t_left = pair.left.timestamp_s;
    if (joint_log) {
      cv::Mat small;
      const double scale =
          std::min(1.0, 160.0 / std::max(1, pair.left.image.cols));
      cv::resize(pair.left.image, small, cv::Size(), scale, scale,
                 cv::INTER_AREA);
      if (small.channels() == 3) cv::cvtColor(small, small, cv::COLOR_BGR2GRAY);
      if (!previous_small.empty()) {
        cv::Mat diff;
        cv::absdiff(small, previous_small, diff);
        motion = cv::mean(diff)[0];
      }
      previous_small = small;
    }
    // Never waits for the disk: a full queue drops the pair (counted).
    if (writer.Submit(std::move(pair))) {
      ++accepted;
      frame_times.push_back(t_left);
      image_motion.push_back(motion);
    } else if (writer.failed()) {
      break;
    }
    pair = capture::StereoFrame();
  }
  const double seconds = elapsed();
  progress.Done();
  grabber.Close();
  s = writer.Stop();  // drains the queue
  if (!s.ok() && failure.empty()) failure = "write: " + s.ToString();
  const int64_t dropped_pairs = writer.dropped_pairs();
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

  capture::SessionSummary summary;
  summary.complete = failure.empty() && stream_bad_input.empty();
  summary.stop_reason = !failure.empty()            ? failure
                        : !stream_bad_input.empty() ? stream_bad_input
                                                    : stop_reason;
  summary.dropped_left = grabber.dropped_left();
  summary.dropped_right = grabber.dropped_right();
  summary.dropped_pairs = dropped_pairs;
  summary.length_mismatch = grabber.length_mismatch();
  summary.seconds = seconds;
  // Joint readings by time, merged before finalizing. A log that cannot be
  // merged is bad input: the session is kept without joint columns.
  std::string joint_error;
  nlohmann::json joints_json;
  if (joint_log && recorder.frames() > 0) {
    frame_times.resize(recorder.frames());
    image_motion.resize(recorder.frames());
    if (!image_motion.empty())
      image_motion[0] = image_motion.size() > 1 ? image_motion[1] : 0.0;
    capture::JointMergeOptions merge_options;
    if (!std::isnan(args.joints_offset)) {
      merge_options.offset_s = args.joints_offset;
    }
    merge_options.max_speed = args.max_joint_speed;
    try {
      const capture::JointMerge merge = capture::MergeJointLog(
          *joint_log, frame_times, image_motion, merge_options);
      s = recorder.SetJointColumns(merge.names, merge.joints);
      if (!s.ok()) throw InputError("capture: " + s.message());
      char offset[64];
      std::snprintf(offset, sizeof(offset), "%.6f", merge.offset_s);
      recorder.SetSetting("joints_log", args.joints);
      recorder.SetSetting("joints_offset_s", offset);
      recorder.SetSetting("joints_offset",
                          merge.estimated ? "estimated" : "given");
      recorder.SetSetting("max_joint_speed",
                          std::to_string(args.max_joint_speed));
      joints_json = {
          {"log", args.joints},
          {"offset_s", merge.offset_s},
          {"offset_estimated", merge.estimated},
          {"agreement", merge.estimated ? nlohmann::json(merge.agreement)
                                        : nlohmann::json()},
          {"stops_matched", merge.stops_matched},
          {"frames_with_reading", merge.with_reading},
          {"frames_too_fast", merge.too_fast}};
    } catch (const InputError& e) {
      joint_error = e.what();
    }
  }
  // The live stream: readings on the controller clock, put on the host
  // clock by the fastest sample; frames outside it get no reading.
  if (stream && recorder.frames() > 0) {
    frame_times.resize(recorder.frames());
    try {
      const capture::JointLog log = stream->Log();
      capture::JointMergeOptions merge_options;
      merge_options.offset_s = stream->OffsetToHost();
      merge_options.max_speed = args.max_joint_speed;
      merge_options.uncovered_ok = true;
      const capture::JointMerge merge =
          capture::MergeJointLog(log, frame_times, {}, merge_options);
      s = recorder.SetJointColumns(merge.names, merge.joints);
      if (!s.ok()) throw InputError("capture: " + s.message());
      recorder.SetSetting("joints_offset_s", std::to_string(merge.offset_s));
      recorder.SetSetting("joints_offset", "stream (fastest sample)");
      joints_json = {{"source", "stream"},
                     {"samples", log.t.size()},
                     {"offset_s", merge.offset_s},
                     {"frames_with_reading", merge.with_reading},
                     {"frames_too_fast", merge.too_fast}};
    } catch (const InputError& e) {
      if (failure.empty() && stream_bad_input.empty()) joint_error = e.what();
    }
  }
  const Status fin = recorder.Finalize(summary);
  if (!fin.ok() && failure.empty()) failure = "finalize: " + fin.ToString();

  if (dropped_pairs > 0) {
    std::cerr << "kincal capture: warning: " << dropped_pairs
              << " stereo pairs dropped because the disk/encoder was slower "
                 "than the cameras (lower --png-compression, add --writers, "
                 "or a faster disk)\n";
  }
  if (grabber.length_mismatch()) {
    std::cerr << "kincal capture: warning: left and right recordings have "
                 "different lengths; recorded the "
              << recorder.frames() << " pairs both have\n";
  }
  if (args.json) {
    nlohmann::json j;
    j["out"] = args.out;
    j["frames"] = recorder.frames();
    j["seconds"] = seconds;
    j["fps"] = seconds > 0 ? recorder.frames() / seconds : 0.0;
    j["bytes"] = recorder.bytes_written();
    j["left"] = left->Describe();
    j["right"] = right->Describe();
    j["pairing"] = info.pairing;
    j["dropped_left"] = grabber.dropped_left();
    j["dropped_right"] = grabber.dropped_right();
    j["dropped_pairs"] = dropped_pairs;
    j["max_queue_depth"] = writer.max_queue_depth();
    j["fast_pairs"] = writer.fast_pairs();
    j["length_mismatch"] = grabber.length_mismatch();
    j["transient_failures"] = transient_failures;
    j["stop_reason"] = summary.stop_reason;
    j["complete"] = failure.empty();
    if (!joints_json.is_null()) j["joints"] = joints_json;
    PrintJson(j);
  } else {
    std::printf(
        "recorded %lld stereo pairs in %.2f s (%.1f pairs/s) to %s\n"
        "pairing: %s, dropped left %lld, right %lld, pairs (disk too slow) "
        "%lld; stopped: %s\n"
        "track it: kincal track --rig RIG.yaml --target TARGET.yaml "
        "--left '%s/left/*.png' --right '%s/right/*.png' --out points.csv\n",
        static_cast<long long>(recorder.frames()), seconds,
        seconds > 0 ? recorder.frames() / seconds : 0.0, args.out.c_str(),
        info.pairing.c_str(), static_cast<long long>(grabber.dropped_left()),
        static_cast<long long>(grabber.dropped_right()),
        static_cast<long long>(dropped_pairs), summary.stop_reason.c_str(),
        args.out.c_str(), args.out.c_str());
  }
  if (!stream_bad_input.empty()) {
    throw InputError("capture: " + stream_bad_input + " (the " +
                     std::to_string(recorder.frames()) +
                     " recorded pairs are kept in " + args.out + ")");
  }
  if (!joint_error.empty()) {
    throw InputError(joint_error + " (the " +
                     std::to_string(recorder.frames()) +
                     " recorded pairs are kept in " + args.out +
                     ", without joint readings)");
  }
  if (!failure.empty()) {
    std::cerr << "kincal: failure: capture: " << failure << " (the "
              << recorder.frames() << " pairs recorded so far are kept in "
              << args.out << ")" << std::endl;
    return 1;
  }
  return 0;
}

}  // namespace

void AddCaptureCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<CaptureArgs>();
  CLI::App* sub = app.add_subcommand("capture", kCaptureDescription);
  auto* list = sub->add_flag("--list", args->list,
                             "list V4L2 devices and Aravis cameras");
  sub->add_option("--left", args->left, "left source URI")->excludes(list);
  sub->add_option("--right", args->right, "right source URI")->excludes(list);
  sub->add_option("--out", args->out,
                  "session folder to create (must not exist or be empty)")
      ->excludes(list);
  sub->add_option("--frames", args->frames, "stop after N pairs")
      ->check(CLI::PositiveNumber);
  sub->add_option("--seconds", args->seconds, "stop after S seconds")
      ->check(CLI::PositiveNumber);
  sub->add_option("--sync-tolerance-ms", args->tolerance_ms,
                  "live cameras: largest left/right time difference of a "
                  "pair (default 10 ms)")
      ->check(CLI::Range(0.001, 1000.0));
  sub->add_option("--png-compression", args->png_compression,
                  "PNG zlib level 0-9, all lossless (default 1: fastest)")
      ->check(CLI::Range(0, 9));
  sub->add_option("--max-failures", args->max_failures,
                  "live cameras: consecutive timeouts/corrupt frames "
                  "tolerated (default 3)")
      ->check(CLI::Range(0, 1000));
  sub->add_option("--joints", args->joints,
                  "controller joint log joints.csv (t, one column per joint) "
                  "merged into frames.csv by time");
  sub->add_option("--robot", args->robot,
                  "robot.yaml: the log's joint columns must be its joints");
  sub->add_option("--joints-offset", args->joints_offset,
                  "clock offset, s: t_frame = t_log + offset (default: "
                  "estimated from when the robot stops)");
  sub->add_option("--max-joint-speed", args->max_joint_speed,
                  "frames taken while a joint moves faster (deg/s or mm/s) "
                  "get no reading (default 1)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--robot-listen", args->robot_listen,
                  "step-and-shoot: wait for the robot on HOST:PORT (line "
                  "protocol in docs/LAB.md) and record one averaged pair per "
                  "settled pose, with the robot's readings");
  sub->add_flag("--stream", args->stream,
                "with --robot-listen: record continuously and fill the "
                "joint columns from the robot's J lines (until BYE)");
  sub->add_option("--shots", args->shots,
                  "pairs grabbed and averaged per settled pose (default 5)")
      ->check(CLI::Range(1, 1000));
  sub->add_option("--robot-timeout", args->robot_timeout,
                  "seconds to wait for the robot (connect, each message)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--queue", args->queue_pairs,
                  "pairs waiting for the writers; when full, new pairs are "
                  "dropped and counted (default 32)")
      ->check(CLI::Range(1, 10000));
  sub->add_option("--writers", args->writers,
                  "writer threads encoding PNGs (default 2)")
      ->check(CLI::Range(1, 64));
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(
      "Example: replay two image folders as a session (no camera needed):\n  "
      "kincal capture --left 'folder:left/*.png?fps=30' --right "
      "'folder:right/*.png?fps=30' --out session --frames 100\nUnits: lengths "
      "mm, angles deg, time s (pixels px). Defaults are shown beside each "
      "option.");
  sub->callback([run, args] { *run = [args] { return RunCapture(*args); }; });
}

}  // namespace kincal::app
