#include "data/progress.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace kincal {

Progress::Progress(std::string task, bool quiet) : task_(std::move(task)) {
  const char* env = std::getenv("KINCAL_PROGRESS");
  if (env != nullptr && std::strcmp(env, "0") == 0) {
    enabled_ = false;
  } else if (env != nullptr && std::strcmp(env, "1") == 0) {
    enabled_ = !quiet;
  } else {
    enabled_ = !quiet && ::isatty(STDERR_FILENO) == 1;
  }
}

Progress::~Progress() { Done(); }

void Progress::Draw(const std::string& text) {
  if (!enabled_) return;
  std::fprintf(stderr, "\r\033[K%s: %s", task_.c_str(), text.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::Stage(const std::string& what) { Draw(what + " ..."); }

void Progress::Update(long done, long total, const std::string& unit) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (done < total && drawn_ && now - last_ < std::chrono::milliseconds(100)) {
    return;
  }
  last_ = now;
  char buf[128];
  std::snprintf(buf, sizeof(buf), "%s%s%ld/%ld (%d %%)", unit.c_str(),
                unit.empty() ? "" : " ", done, total,
                total > 0 ? static_cast<int>(100 * done / total) : 100);
  Draw(buf);
}

void Progress::Done() {
  if (enabled_ && drawn_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
  }
  drawn_ = false;
}

}  // namespace kincal
