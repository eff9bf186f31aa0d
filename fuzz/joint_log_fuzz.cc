// libFuzzer target: a robot controller's joint log joints.csv (`kincal capture
// --joints`; capture/joint_log.h), parsed with and without the robot's joint
// names and, when it parses, merged into frame times (given offset and
// estimated offset). Any input must end in a value or an InputError (the
// CLI's exit 2); anything else (a crash, a sanitizer report, another exception
// type, a hang) is a finding.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "capture/joint_log.h"
#include "data/error.h"

namespace {

void Merge(const kincal::capture::JointLog& log) {
  // Frames spread over the middle half of the log's time span (at most 64,
  // so that a range of clock offsets is possible), the image motion
  // alternating between still and moving every few frames.
  const int n = static_cast<int>(std::min<size_t>(log.t.size(), 64));
  const double span = log.t.back() - log.t.front();
  std::vector<double> times, motion;
  for (int i = 0; i < n; ++i) {
    times.push_back(log.t.front() + 0.25 * span +
                    0.5 * span * i / std::max(1, n - 1));
    motion.push_back((i / 3) % 2 ? 5.0 : 0.1);
  }
  kincal::capture::JointMergeOptions given;
  given.offset_s = 0.0;
  given.uncovered_ok = true;
  kincal::capture::JointMergeOptions estimated;
  for (const auto* options : {&given, &estimated}) {
    try {
      kincal::capture::MergeJointLog(log, times, motion, *options);
    } catch (const kincal::InputError&) {
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::vector<std::string> robot = {"j1", "j2", "j3", "j4", "j5"};
  for (const std::vector<std::string>* expected :
       {static_cast<const std::vector<std::string>*>(nullptr), &robot}) {
    try {
      const kincal::capture::JointLog log =
          kincal::capture::ParseJointLog(text, "joints.csv", expected);
      if (expected == nullptr) Merge(log);
    } catch (const kincal::InputError&) {
    }
  }
  return 0;
}
