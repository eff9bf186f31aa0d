// Capture throughput on this machine:
//   BM_RecordStereoPair/<png level>/<channels>: SessionRecorder::Write of one
//     1280x1024 pair (PNG encode + write + rename, both sides), pairs/s;
//   BM_EncodePng/<png level>: cv::imencode of one 1280x1024 gray image;
//   BM_EncodePngLibpng/<png level>: the recorder's encoder, same image;
//   BM_FolderReplay: FrameGrabber over two folders of 1280x1024 PNGs, pairs/s;
//   BM_Convert*: one 1280x1024 camera buffer to cv::Mat.
// The images are a smooth scene plus sensor-like noise (sigma 2 grey levels),
// which compresses like a real camera frame (pure noise would not compress).

#include <benchmark/benchmark.h>
#include <stdlib.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "capture/frame_grabber.h"
#include "capture/frame_source.h"
#include "capture/pixel_convert.h"
#include "capture/png_encode.h"
#include "capture/recorder.h"

namespace kincal::capture {
namespace {

constexpr int kWidth = 1280;
constexpr int kHeight = 1024;

cv::Mat SceneImage(int channels, int seed) {
  cv::Mat gray(kHeight, kWidth, CV_8UC1);
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 0; c < kWidth; ++c) {
      gray.at<uint8_t>(r, c) = static_cast<uint8_t>(
          60 + 40 * ((r / 64 + c / 64 + seed) % 2) + (r + c) / 40);
    }
  }
  cv::circle(gray, {640, 512}, 200, cv::Scalar(220), -1);
  cv::Mat noise(kHeight, kWidth, CV_16SC1);
  cv::theRNG().state = 1234 + seed;
  cv::randn(noise, 0, 2);
  gray.convertTo(gray, CV_16SC1);
  gray += noise;
  gray.convertTo(gray, CV_8UC1);
  if (channels == 1) return gray;
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

std::string TempDir(const char* tag) {
  std::string templ = std::string("/tmp/kincal_bench_") + tag + "_XXXXXX";
  char* dir = ::mkdtemp(templ.data());
  return dir ? dir : "";
}

void RemoveDir(const std::string& dir) {
  if (dir.rfind("/tmp/kincal_bench_", 0) == 0) {
    const int rc = std::system(("rm -rf '" + dir + "'").c_str());
    (void)rc;
  }
}

void BM_RecordStereoPair(benchmark::State& state) {
  const int level = static_cast<int>(state.range(0));
  const int channels = static_cast<int>(state.range(1));
  FrameSet pair;
  pair.frames.resize(2);
  pair.frames[0].image = SceneImage(channels, 0);
  pair.frames[1].image = SceneImage(channels, 1);
  const std::string dir = TempDir("rec");
  SessionRecorder::Options options;
  options.png_compression = level;
  SessionRecorder recorder(options);
  SessionInfo info;
  info.cameras = {{"left", "", "", ""}, {"right", "", "", ""}};
  if (!recorder.Open(dir + "/s", info).ok()) {
    state.SkipWithError("cannot open the session");
    return;
  }
  for (auto _ : state) {
    const Status s = recorder.Write(pair);
    if (!s.ok()) {
      state.SkipWithError(s.ToString().c_str());
      break;
    }
  }
  recorder.Finalize({});
  state.SetItemsProcessed(state.iterations());  // pairs
  state.counters["MB_per_pair"] =
      recorder.frames() > 0 ? recorder.bytes_written() / 1e6 / recorder.frames()
                            : 0.0;
  RemoveDir(dir);
}
BENCHMARK(BM_RecordStereoPair)
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({3, 1})
    ->Args({6, 1})
    ->Args({1, 3})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// PNG encoding alone (no disk), one 1280x1024 gray image.
void BM_EncodePng(benchmark::State& state) {
  const cv::Mat image = SceneImage(1, 0);
  std::vector<uchar> png;
  for (auto _ : state) {
    cv::imencode(
        ".png", image, png,
        {cv::IMWRITE_PNG_COMPRESSION, static_cast<int>(state.range(0))});
    benchmark::DoNotOptimize(png.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EncodePng)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The recorder's encoder (capture/png_encode.h: libpng, fixed filter).
void BM_EncodePngLibpng(benchmark::State& state) {
  const cv::Mat image = SceneImage(1, 0);
  std::vector<uint8_t> png;
  std::string error;
  for (auto _ : state) {
    EncodePng(image, static_cast<int>(state.range(0)), &png, &error);
    benchmark::DoNotOptimize(png.data());
  }
  state.counters["bytes"] = static_cast<double>(png.size());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EncodePngLibpng)
    ->Arg(0)
    ->Arg(1)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond);

void BM_FolderReplay(benchmark::State& state) {
  constexpr int kImages = 16;
  const std::string dir = TempDir("replay");
  const cv::Mat left = SceneImage(1, 0);
  const cv::Mat right = SceneImage(1, 1);
  for (int i = 0; i < kImages; ++i) {
    Status s =
        WritePngAtomic(dir + "/l_" + std::to_string(100 + i) + ".png", left, 1);
    if (s.ok()) {
      s = WritePngAtomic(dir + "/r_" + std::to_string(100 + i) + ".png", right,
                         1);
    }
    if (!s.ok()) {
      state.SkipWithError(s.ToString().c_str());
      return;
    }
  }
  int64_t pairs = 0;
  for (auto _ : state) {
    auto l = MakeFrameSource("folder:" + dir + "/l_*.png");
    auto r = MakeFrameSource("folder:" + dir + "/r_*.png");
    FrameGrabber grabber({l.get(), r.get()});
    if (!grabber.Open().ok()) {
      state.SkipWithError("cannot open");
      break;
    }
    FrameSet pair;
    while (grabber.Grab(&pair).ok()) ++pairs;
  }
  state.SetItemsProcessed(pairs);
  RemoveDir(dir);
}
BENCHMARK(BM_FolderReplay)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ConvertYuyv(benchmark::State& state) {
  std::vector<uint8_t> raw(kWidth * kHeight * 2, 128);
  PixelBuffer b{raw.data(), raw.size(), kWidth, kHeight, 0, PixelLayout::kYuyv};
  cv::Mat out;
  for (auto _ : state) benchmark::DoNotOptimize(ConvertToMat(b, &out));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ConvertYuyv)->Unit(benchmark::kMillisecond);

void BM_ConvertBayer8(benchmark::State& state) {
  std::vector<uint8_t> raw(kWidth * kHeight, 100);
  PixelBuffer b{raw.data(), raw.size(), kWidth,
                kHeight,    0,          PixelLayout::kBayer8};
  cv::Mat out;
  for (auto _ : state) benchmark::DoNotOptimize(ConvertToMat(b, &out));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ConvertBayer8)->Unit(benchmark::kMillisecond);

void BM_ConvertMono12(benchmark::State& state) {
  std::vector<uint8_t> raw(kWidth * kHeight * 2, 7);
  PixelBuffer b{raw.data(), raw.size(), kWidth,
                kHeight,    0,          PixelLayout::kGray16};
  b.bits = 12;
  cv::Mat out;
  for (auto _ : state) benchmark::DoNotOptimize(ConvertToMat(b, &out));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ConvertMono12)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace kincal::capture

BENCHMARK_MAIN();
