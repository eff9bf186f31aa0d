#ifndef KINCAL_DATA_PROGRESS_H_
#define KINCAL_DATA_PROGRESS_H_

// Progress of a long command on a terminal: one line on stderr, rewritten in
// place ("kincal track: frame 120/400 (30 %)"), cleared when done. Silent
// when stderr is not a TTY (pipes, CI, tests) and with --json, so machine
// output never carries it. KINCAL_PROGRESS=1 forces it on (tests),
// KINCAL_PROGRESS=0 off.

#include <chrono>
#include <string>

namespace kincal {

class Progress {
 public:
  // `task` prefixes every line, e.g. "kincal track"; `quiet` (set it from
  // --json) turns it off.
  Progress(std::string task, bool quiet);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  bool enabled() const { return enabled_; }
  // A named stage ("calibrating the geometry").
  void Stage(const std::string& what);
  // Counted work; redraws at most 10 times per second and at the end.
  void Update(long done, long total, const std::string& unit = "");
  // Clears the line.
  void Done();

 private:
  void Draw(const std::string& text);
  std::string task_;
  bool enabled_ = false;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace kincal

#endif  // KINCAL_DATA_PROGRESS_H_
