// Sustained recording rate, as `kincal capture` records: StereoGrabber over
// two sources -> AsyncRecorder (bounded queue, writer threads) ->
// SessionRecorder (PNG via libpng, journal). Live: two fake cameras
// (capture/fake_source.cc, 1280x1024 gray, 30 fps, paced in real time) for
// `seconds` (argv[1], default 60) at PNG levels 0 and 1. Replay: the
// recorded level-1 session's folders replayed into a new session as fast as
// possible. Sessions go under $TMPDIR (default /tmp) and are removed.

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "capture/async_recorder.h"
#include "capture/frame_source.h"
#include "capture/recorder.h"
#include "capture/stereo_grabber.h"

namespace kincal::capture {
namespace {

struct Figures {
  int64_t pairs = 0, dropped_pairs = 0, dropped_left = 0, dropped_right = 0;
  int max_queue = 0;
  int64_t fast = 0;
  double seconds = 0;
  uint64_t bytes = 0;
};

Figures Record(const std::string& left_uri, const std::string& right_uri,
               const std::string& dir, int level, double seconds) {
  auto left = MakeFrameSource(left_uri);
  auto right = MakeFrameSource(right_uri);
  StereoGrabber grabber(left.get(), right.get());
  Figures f;
  if (!grabber.Open().ok()) return f;
  SessionInfo info;
  info.left_uri = left_uri;
  info.right_uri = right_uri;
  info.live = left->IsLive();
  SessionRecorder::Options options;
  options.png_compression = level;
  SessionRecorder recorder(options);
  if (!recorder.Open(dir, info).ok()) return f;
  AsyncRecorderOptions async;
  async.drop_when_full = left->IsLive();
  AsyncRecorder writer(&recorder, async);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  StereoFrame pair;
  while (seconds <= 0 || elapsed() < seconds) {
    const Status s = grabber.Grab(&pair);
    if (!s.ok()) break;
    writer.Submit(std::move(pair));
    pair = StereoFrame();
  }
  writer.Stop();
  f.seconds = elapsed();
  grabber.Close();
  SessionSummary summary;
  recorder.Finalize(summary);
  f.pairs = recorder.frames();
  f.dropped_pairs = writer.dropped_pairs();
  f.dropped_left = grabber.dropped_left();
  f.dropped_right = grabber.dropped_right();
  f.max_queue = writer.max_queue_depth();
  f.fast = writer.fast_pairs();
  f.bytes = recorder.bytes_written();
  return f;
}

void Print(const char* what, const Figures& f) {
  std::printf(
      "%-34s %6lld pairs %7.2f s %6.2f pairs/s | dropped pairs (queue full) "
      "%lld | unpaired left/right %lld/%lld | max queue %d | level-0 pairs "
      "%lld | %.1f MB/s\n",
      what, static_cast<long long>(f.pairs), f.seconds, f.pairs / f.seconds,
      static_cast<long long>(f.dropped_pairs),
      static_cast<long long>(f.dropped_left),
      static_cast<long long>(f.dropped_right), f.max_queue,
      static_cast<long long>(f.fast), f.bytes / 1e6 / f.seconds);
}

}  // namespace
}  // namespace kincal::capture

int main(int argc, char** argv) {
  using namespace kincal::capture;
  const double seconds = argc > 1 ? std::atof(argv[1]) : 60.0;
  const char* tmp = std::getenv("TMPDIR");
  const std::string base = std::string(tmp ? tmp : "/tmp") +
                           "/kincal_capture_rate_" + std::to_string(::getpid());
  const std::string cam = "?width=1280&height=1024&fps=30";
  for (int level : {0, 1}) {
    const std::string dir = base + "/live" + std::to_string(level);
    const Figures f =
        Record("fake:left" + cam, "fake:right" + cam, dir, level, seconds);
    char what[64];
    std::snprintf(what, sizeof(what), "live 2x1280x1024@30, PNG level %d",
                  level);
    Print(what, f);
  }
  const Figures r =
      Record("folder:" + base + "/live1/left/*.png",
             "folder:" + base + "/live1/right/*.png", base + "/replay", 1, 0);
  Print("replay of the level-1 session", r);
  return std::system(("rm -rf '" + base + "'").c_str()) == 0 ? 0 : 1;
}
