// kincal capture: record a session (one image folder per camera, named as in
// rig.yaml, frames.csv, session.yaml) from 1..N cameras or recordings, in
// the layout `kincal track --session` and `kincal bundle` read directly;
// `kincal capture --list` lists cameras.

#include <signal.h>

#include <atomic>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "app/app_util.h"
#include "app/command.h"
#include "app/front_end.h"
#include "capture/capture_session.h"
#include "capture/frame_grabber.h"
#include "capture/frame_source.h"
#include "data/error.h"
#include "data/session.h"

namespace kincal::app {
namespace {

using capture::Status;

struct CaptureArgs {
  capture::CaptureOptions options;
  std::vector<std::string> cameras;  // --camera NAME=URI
  std::string left, right;           // the two-camera spelling
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

nlohmann::json JointsJson(const capture::CaptureJoints& joints) {
  if (joints.from_stream) {
    return {{"source", "stream"},
            {"samples", joints.samples},
            {"offset_s", joints.offset_s},
            {"frames_with_reading", joints.frames_with_reading},
            {"frames_too_fast", joints.frames_too_fast}};
  }
  return {
      {"log", joints.log},
      {"offset_s", joints.offset_s},
      {"offset_estimated", joints.offset_estimated},
      {"agreement", joints.offset_estimated ? nlohmann::json(joints.agreement)
                                            : nlohmann::json()},
      {"stops_matched", joints.stops_matched},
      {"frames_with_reading", joints.frames_with_reading},
      {"frames_too_fast", joints.frames_too_fast}};
}

// Every camera: name, uri, description, dropped.
nlohmann::json CapturedCamerasJson(
    const std::vector<capture::CapturedCamera>& cameras) {
  nlohmann::json out = nlohmann::json::array();
  for (const capture::CapturedCamera& c : cameras) {
    out.push_back({{"name", c.name},
                   {"uri", c.uri},
                   {"description", c.description},
                   {"dropped", c.dropped}});
    if (!c.mosaic.empty()) out.back()["mosaic"] = c.mosaic;
  }
  return out;
}

nlohmann::json StepAndShootJson(const capture::CaptureOptions& options,
                                const capture::CaptureResult& result) {
  const capture::StepAndShootResult& r = result.step;
  nlohmann::json j;
  j["out"] = options.out;
  j["mode"] = "step_and_shoot";
  j["frames"] = r.frames;
  j["poses"] = r.poses;
  j["cameras"] = CapturedCamerasJson(result.cameras);
  j["shots_per_pose"] = options.shots;
  j["robot"] = r.robot_name;
  j["joint_stream"] = r.joint_stream;
  j["seconds"] = r.seconds;
  j["stop_reason"] = r.stop_reason;
  j["complete"] = r.complete;
  return j;
}

// `frames` counts the recorded sets (one image per camera); dropped_pairs
// and fast_pairs count sets too (their names date from two cameras). A
// two-camera recording also carries left, right, dropped_left and
// dropped_right for its first and second camera.
nlohmann::json RecordingJson(const capture::CaptureOptions& options,
                             const capture::CaptureResult& r) {
  nlohmann::json j;
  j["out"] = options.out;
  j["frames"] = r.frames;
  j["seconds"] = r.seconds;
  j["fps"] = r.seconds > 0 ? r.frames / r.seconds : 0.0;
  j["bytes"] = r.bytes;
  j["cameras"] = CapturedCamerasJson(r.cameras);
  if (r.cameras.size() == 2) {
    j["left"] = r.cameras[0].description;
    j["right"] = r.cameras[1].description;
    j["dropped_left"] = r.cameras[0].dropped;
    j["dropped_right"] = r.cameras[1].dropped;
  }
  j["pairing"] = r.pairing;
  j["dropped_pairs"] = r.dropped_sets;
  j["max_queue_depth"] = r.max_queue_depth;
  j["fast_pairs"] = r.fast_sets;
  j["length_mismatch"] = r.length_mismatch;
  j["transient_failures"] = r.transient_failures;
  j["stop_reason"] = r.stop_reason;
  j["complete"] = r.complete;
  if (r.has_joints) j["joints"] = JointsJson(r.joints);
  AddWarnings(r.warnings, &j);
  return j;
}

void PrintStepAndShoot(const CaptureArgs& args,
                       const capture::CaptureResult& result) {
  const capture::StepAndShootResult& r = result.step;
  if (!r.session_created) return;
  if (args.json) {
    PrintJson(StepAndShootJson(args.options, result));
    return;
  }
  std::printf(
      "recorded %ld settled poses (%d %s averaged each) to %s; "
      "stopped: %s\n",
      r.poses, args.options.shots,
      capture::FrameSetNoun(args.options.cameras.size()),
      args.options.out.c_str(), r.stop_reason.c_str());
}

// The merged joint readings in words: the clock offset, how it was found
// and, when estimated, its agreement with the images.
void PrintJoints(const capture::CaptureJoints& joints) {
  if (joints.from_stream) {
    std::printf(
        "joints: %lld stream readings, clock offset %.3f s (fastest "
        "sample)",
        static_cast<long long>(joints.samples), joints.offset_s);
  } else if (joints.offset_estimated) {
    std::printf(
        "joints: %s, clock offset %.3f s estimated (agreement with "
        "the images %.0f%% of the frames, %d stops matched)",
        joints.log.c_str(), joints.offset_s, 100.0 * joints.agreement,
        joints.stops_matched);
  } else {
    std::printf("joints: %s, clock offset %.3f s (given)", joints.log.c_str(),
                joints.offset_s);
  }
  std::printf("; %d frames with a reading, %d too fast\n",
              joints.frames_with_reading, joints.frames_too_fast);
}

void PrintRecording(const CaptureArgs& args, const capture::CaptureResult& r) {
  if (!r.recorded) return;
  const char* noun = capture::FrameSetNoun(r.cameras.size());
  if (r.dropped_sets > 0) {
    std::cerr << "kincal capture: warning: " << r.dropped_sets << " " << noun
              << " dropped because the disk/encoder was slower than the "
                 "cameras (lower --png-compression, add --writers, or a "
                 "faster disk)\n";
  }
  if (r.length_mismatch) {
    std::cerr << "kincal capture: warning: the recordings have different "
                 "lengths; recorded the "
              << r.frames << " " << noun << " they all have\n";
  }
  if (args.json) {
    PrintJson(RecordingJson(args.options, r));
    return;
  }
  std::string dropped;
  for (const capture::CapturedCamera& c : r.cameras) {
    dropped += c.name + " " + std::to_string(c.dropped) + ", ";
  }
  const std::string& out = args.options.out;
  std::printf(
      "recorded %lld %s (%zu camera%s) in %.2f s (%.1f/s) to %s\n"
      "pairing: %s, dropped %s%s (disk too slow) %lld; stopped: %s\n"
      "track it: kincal track --rig RIG.yaml --target TARGET.yaml "
      "--session '%s' --out points.csv\n",
      static_cast<long long>(r.frames), noun, r.cameras.size(),
      r.cameras.size() == 1 ? "" : "s", r.seconds,
      r.seconds > 0 ? r.frames / r.seconds : 0.0, out.c_str(),
      r.pairing.c_str(), dropped.c_str(), noun,
      static_cast<long long>(r.dropped_sets), r.stop_reason.c_str(),
      out.c_str());
  if (r.has_joints) PrintJoints(r.joints);
}

// Parse -> record (capture/capture_session.h) -> print. Ctrl-C stops the
// recording, which is then finalized.
int RunCapture(const CaptureArgs& args) {
  if (args.list) return RunList(args);
  capture::CaptureOptions options = args.options;
  // --camera NAME=URI (1..N, rig order: the names are the session's image
  // folders and frames.csv columns) or the two-camera --left/--right.
  if (!args.left.empty() && args.right.empty() && args.cameras.empty()) {
    throw InputError(
        "capture: --right is required with --left (the two-camera "
        "spelling); for one camera give --camera NAME=URI");
  }
  for (const CameraGlob& c : CameraGlobs(args.cameras, args.left, args.right)) {
    CheckSessionCameraName(c.name, c.option);
    options.cameras.push_back({c.name, c.glob});
  }
  options.announce = !args.json;
  options.interrupted = &g_interrupted;
  std::optional<InterruptGuard> guard;
  options.before_recording = [&guard] { guard.emplace(); };
  const capture::CaptureResult result = capture::RunCaptureSession(options);
  if (result.step_and_shoot) {
    PrintStepAndShoot(args, result);
  } else {
    PrintRecording(args, result);
  }
  if (result.outcome == capture::CaptureResult::kBadInput) {
    throw InputError(result.message);
  }
  if (result.outcome == capture::CaptureResult::kFailure) {
    std::cerr << "kincal: failure: " << result.message << std::endl;
    return 1;
  }
  return 0;
}

}  // namespace

void AddCaptureCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<CaptureArgs>();
  capture::CaptureOptions& o = args->options;
  CLI::App* sub = app.add_subcommand("capture", kCaptureDescription);
  auto* list = sub->add_flag("--list", args->list,
                             "list V4L2 devices and Aravis cameras");
  AddCameraOption(sub, &args->cameras,
                  "NAME=URI: a camera named as in rig.yaml (its image folder "
                  "and frames.csv columns) and its source; once per camera "
                  "(1..N), in rig order")
      ->type_name("NAME=URI")
      ->excludes(list);
  sub->add_option("--left", args->left,
                  "left source URI (with --right: the two-camera spelling of "
                  "--camera left=URI --camera right=URI)")
      ->excludes(list);
  sub->add_option("--right", args->right, "right source URI")->excludes(list);
  sub->add_option("--out", o.out,
                  "session folder to create (must not exist or be empty)")
      ->excludes(list);
  sub->add_option("--frames", o.frames,
                  "stop after N frame sets (one image per camera)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--seconds", o.seconds, "stop after S seconds")
      ->check(CLI::PositiveNumber);
  sub->add_option("--sync-tolerance-ms", o.tolerance_ms,
                  "live cameras: largest time difference within a frame set "
                  "(default 10 ms)")
      ->check(CLI::Range(0.001, 1000.0));
  sub->add_option("--png-compression", o.png_compression,
                  "PNG zlib level 0-9, all lossless (default 1: fastest)")
      ->check(CLI::Range(0, 9));
  sub->add_option("--max-failures", o.max_failures,
                  "live cameras: consecutive timeouts/corrupt frames "
                  "tolerated (default 3)")
      ->check(CLI::Range(0, 1000));
  sub->add_option("--joints", o.joints,
                  "controller joint log joints.csv (t, one column per joint) "
                  "merged into frames.csv by time");
  sub->add_option("--robot", o.robot,
                  "robot.yaml: the log's joint columns must be its joints");
  sub->add_option("--joints-offset", o.joints_offset,
                  "clock offset, s: t_frame = t_log + offset (default: "
                  "estimated from when the robot stops)");
  sub->add_option("--max-joint-speed", o.max_joint_speed,
                  "frames taken while a joint moves faster (deg/s or mm/s) "
                  "get no reading (default 1)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--robot-listen", o.robot_listen,
                  "step-and-shoot: wait for the robot on HOST:PORT (line "
                  "protocol in docs/LAB.md) and record one averaged frame set "
                  "per settled pose, with the robot's readings");
  sub->add_flag("--stream", o.stream,
                "with --robot-listen: record continuously and fill the "
                "joint columns from the robot's J lines (until BYE)");
  sub->add_option("--shots", o.shots,
                  "frame sets grabbed and averaged per settled pose (default "
                  "5)")
      ->check(CLI::Range(1, 1000));
  sub->add_option("--robot-timeout", o.robot_timeout,
                  "seconds to wait for the robot (connect, each message)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--queue", o.queue_sets,
                  "frame sets waiting for the writers; when full, new sets "
                  "are dropped and counted (default 32)")
      ->check(CLI::Range(1, 10000));
  sub->add_option("--writers", o.writers,
                  "writer threads encoding PNGs (default 2)")
      ->check(CLI::Range(1, 64));
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Examples (no camera needed): replay two image folders as a session,\n"
      "  kincal capture --left 'folder:left/*.png?fps=30' --right "
      "'folder:right/*.png?fps=30' --out session --frames 100\n"
      "three cameras named as in rig.yaml (one folder each in the session),\n"
      "  kincal capture --camera left='v4l2:/dev/video0' --camera "
      "right='v4l2:/dev/video2' --camera top='v4l2:/dev/video4' --out "
      "session --seconds 60"));
  sub->callback([run, args] { *run = [args] { return RunCapture(*args); }; });
}

}  // namespace kincal::app
