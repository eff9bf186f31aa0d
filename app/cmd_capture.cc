// kincal capture: record a stereo session (left/*.png, right/*.png,
// frames.csv, session.yaml) from two cameras or two recordings, in the layout
// `kincal track` reads directly; `kincal capture --list` lists cameras.

#include <dirent.h>
#include <signal.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "app/command.h"
#include "capture/frame_source.h"
#include "capture/recorder.h"
#include "capture/stereo_grabber.h"
#include "data/error.h"

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
  Require(IsAbsentOrEmptyDir(args.out),
          "capture: --out " + args.out +
              " exists and is not empty; kincal never overwrites a session, "
              "choose a new folder");
  const bool live = left->IsLive();

  capture::StereoGrabberOptions options;
  options.tolerance_s = args.tolerance_ms * 1e-3;
  capture::StereoGrabber grabber(left.get(), right.get(), options);
  Status s = grabber.Open();
  if (!s.ok()) {
    // A missing replay file is bad input; a missing camera a failure.
    if (!live && s.kind() == Status::Kind::kNotFound) {
      throw InputError("capture: " + s.message());
    }
    std::cerr << "kincal: failure: capture: " << s.ToString() << std::endl;
    return 1;
  }

  capture::SessionInfo info;
  info.left_uri = args.left;
  info.right_uri = args.right;
  info.left_description = left->Describe();
  info.right_description = right->Describe();
  info.live = live;
  info.pairing = capture::PairingName(grabber.pairing());
  info.tolerance_s =
      grabber.pairing() == capture::StereoGrabber::Pairing::kLockStep
          ? 0.0
          : options.tolerance_s;
  info.time_base = capture::TimeBaseName(left->time_base());
  if (args.frames > 0) info.settings["frames"] = std::to_string(args.frames);
  if (args.seconds > 0) info.settings["seconds"] = std::to_string(args.seconds);
  info.settings["png_compression"] = std::to_string(args.png_compression);

  capture::SessionRecorder::Options rec_options;
  rec_options.png_compression = args.png_compression;
  capture::SessionRecorder recorder(rec_options);
  s = recorder.Open(args.out, info);
  if (!s.ok()) {
    std::cerr << "kincal: failure: capture: " << s.ToString() << std::endl;
    return 1;
  }
  if (live && args.frames == 0 && args.seconds == 0 && !args.json) {
    std::cerr << "kincal capture: recording until Ctrl-C\n";
  }

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
  for (;;) {
    if (args.frames > 0 && recorder.frames() >= args.frames) {
      stop_reason = "frames";
      break;
    }
    if (args.seconds > 0 && elapsed() >= args.seconds) {
      stop_reason = "seconds";
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
    s = recorder.Write(pair);
    if (!s.ok()) {
      failure = "write: " + s.ToString();
      break;
    }
  }
  const double seconds = elapsed();
  grabber.Close();

  capture::SessionSummary summary;
  summary.complete = failure.empty();
  summary.stop_reason = failure.empty() ? stop_reason : failure;
  summary.dropped_left = grabber.dropped_left();
  summary.dropped_right = grabber.dropped_right();
  summary.length_mismatch = grabber.length_mismatch();
  summary.seconds = seconds;
  const Status fin = recorder.Finalize(summary);
  if (!fin.ok() && failure.empty()) failure = "finalize: " + fin.ToString();

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
    j["length_mismatch"] = grabber.length_mismatch();
    j["transient_failures"] = transient_failures;
    j["stop_reason"] = summary.stop_reason;
    j["complete"] = failure.empty();
    PrintJson(j);
  } else {
    std::printf(
        "recorded %lld stereo pairs in %.2f s (%.1f pairs/s) to %s\n"
        "pairing: %s, dropped left %lld, right %lld; stopped: %s\n"
        "track it: kincal track --rig RIG.yaml --target TARGET.yaml "
        "--left '%s/left/*.png' --right '%s/right/*.png' --out points.csv\n",
        static_cast<long long>(recorder.frames()), seconds,
        seconds > 0 ? recorder.frames() / seconds : 0.0, args.out.c_str(),
        info.pairing.c_str(), static_cast<long long>(grabber.dropped_left()),
        static_cast<long long>(grabber.dropped_right()),
        summary.stop_reason.c_str(), args.out.c_str(), args.out.c_str());
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
  CLI::App* sub = app.add_subcommand(
      "capture",
      "Record a stereo session (left/*.png, right/*.png, frames.csv, "
      "session.yaml) from two cameras or two recordings; --list shows "
      "cameras. Sources: v4l2:/dev/videoN?width=..&height=..&fps=..&format="
      "GREY|YUYV|MJPG, aravis:<camera id>?exposure_us=..&gain=..&fps=..&"
      "format=Mono8|..., folder:/path/left*.png?fps=.., video:/path/file.mp4");
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
