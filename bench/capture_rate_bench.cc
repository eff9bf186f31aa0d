// Sustained recording rate, as `kincal capture` records: FrameGrabber over
// N sources -> AsyncRecorder (bounded queue, writer threads) ->
// SessionRecorder (PNG via libpng, journal). Live: N fake cameras
// (capture/fake_source.cc, 1280x1024 gray, 30 fps, paced in real time) for
// `seconds` (argv[1], default 60) at PNG levels 0 and 1; N is argv[2]
// (default 2). Replay: the recorded level-1 session's folders replayed into
// a new session as fast as possible. Sessions go under $TMPDIR (default
// /tmp) and are removed.
//
//   build/bin/capture_rate_bench 60 3     # three cameras, 60 s per level

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "capture/async_recorder.h"
#include "capture/frame_grabber.h"
#include "capture/frame_source.h"
#include "capture/recorder.h"

namespace kincal::capture {
namespace {

struct Figures {
  int64_t sets = 0, dropped_sets = 0;
  std::vector<int64_t> dropped;  // per camera: frames in no set
  int max_queue = 0;
  int64_t fast = 0;
  double seconds = 0;
  uint64_t bytes = 0;
};

// Records the sources (one per camera name) into `dir` for `seconds`
// (0: until a replay ends).
Figures Record(const std::vector<std::string>& names,
               const std::vector<std::string>& uris, const std::string& dir,
               int level, double seconds) {
  std::vector<std::unique_ptr<FrameSource>> sources;
  std::vector<FrameSource*> pointers;
  SessionInfo info;
  for (size_t k = 0; k < uris.size(); ++k) {
    sources.push_back(MakeFrameSource(uris[k]));
    pointers.push_back(sources.back().get());
    info.cameras.push_back({names[k], uris[k], sources.back()->Describe(),
                            sources.back()->mosaic()});
  }
  FrameGrabber grabber(pointers);
  Figures f;
  if (!grabber.Open().ok()) return f;
  info.live = sources[0]->IsLive();
  SessionRecorder::Options options;
  options.png_compression = level;
  SessionRecorder recorder(options);
  if (!recorder.Open(dir, info).ok()) return f;
  AsyncRecorderOptions async;
  async.drop_when_full = info.live;
  AsyncRecorder writer(&recorder, async);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  FrameSet set;
  while (seconds <= 0 || elapsed() < seconds) {
    const Status s = grabber.Grab(&set);
    if (!s.ok()) break;
    writer.Submit(std::move(set));
    set = FrameSet();
  }
  writer.Stop();
  f.seconds = elapsed();
  grabber.Close();
  SessionSummary summary;
  recorder.Finalize(summary);
  f.sets = recorder.frames();
  f.dropped_sets = writer.dropped_sets();
  f.dropped = grabber.dropped();
  f.max_queue = writer.max_queue_depth();
  f.fast = writer.fast_sets();
  f.bytes = recorder.bytes_written();
  return f;
}

void Print(const char* what, const Figures& f) {
  std::string dropped;
  for (int64_t d : f.dropped) {
    dropped += (dropped.empty() ? "" : "/") + std::to_string(d);
  }
  std::printf(
      "%-34s %6lld sets %7.2f s %6.2f sets/s | dropped sets (queue full) "
      "%lld | frames in no set per camera %s | max queue %d | level-0 sets "
      "%lld | %.1f MB/s\n",
      what, static_cast<long long>(f.sets), f.seconds, f.sets / f.seconds,
      static_cast<long long>(f.dropped_sets), dropped.c_str(), f.max_queue,
      static_cast<long long>(f.fast), f.bytes / 1e6 / f.seconds);
}

}  // namespace
}  // namespace kincal::capture

int main(int argc, char** argv) {
  using namespace kincal::capture;
  const double seconds = argc > 1 ? std::atof(argv[1]) : 60.0;
  const int cameras = argc > 2 ? std::atoi(argv[2]) : 2;
  if (seconds <= 0 || cameras < 1 || cameras > 16) {
    std::fprintf(stderr,
                 "usage: capture_rate_bench [seconds > 0] [cameras 1..16]\n");
    return 2;
  }
  const char* tmp = std::getenv("TMPDIR");
  const std::string base = std::string(tmp ? tmp : "/tmp") +
                           "/kincal_capture_rate_" + std::to_string(::getpid());
  std::vector<std::string> names;
  for (int k = 0; k < cameras; ++k) names.push_back("cam" + std::to_string(k));
  std::vector<std::string> live, replay;
  for (const std::string& n : names) {
    live.push_back("fake:" + n + "?width=1280&height=1024&fps=30");
    replay.push_back("folder:" + base + "/live1/" + n + "/*.png");
  }
  for (int level : {0, 1}) {
    const Figures f = Record(
        names, live, base + "/live" + std::to_string(level), level, seconds);
    char what[64];
    std::snprintf(what, sizeof(what), "live %dx1280x1024@30, PNG level %d",
                  cameras, level);
    Print(what, f);
  }
  const Figures r = Record(names, replay, base + "/replay", 1, 0);
  Print("replay of the level-1 session", r);
  return std::system(("rm -rf '" + base + "'").c_str()) == 0 ? 0 : 1;
}
