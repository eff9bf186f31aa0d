#ifndef KINCAL_CAPTURE_ASYNC_RECORDER_H_
#define KINCAL_CAPTURE_ASYNC_RECORDER_H_

// Recording at camera rate: the grab loop hands each frame set (one image
// per camera, capture/frame_grabber.h) to Submit, which
// never waits for the disk; a bounded queue feeds writer threads that encode
// and write the PNGs (SessionRecorder::WriteSetImages), and the rows are
// committed to the session's journal in frame order as soon as every
// earlier frame is on disk.
//
// When the disk (or the encoder) is slower than the cameras the queue fills
// and Submit drops the set: it is counted (dropped_sets) and never
// numbered, so frame names stay contiguous and the grab loop never blocks.
// The guarantees of SessionRecorder hold: no partial sets (a failed set's
// images are removed), and after kill -9 the journal frames.csv.part lists
// only frames whose images are all complete, in order.
//
// After the first write failure the recorder stops accepting sets (Submit
// returns false), the frames committed so far stay, and the images of
// frames written after the failed one are removed; Stop reports the error.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "capture/recorder.h"

namespace kincal::capture {

struct AsyncRecorderOptions {
  // Sets waiting for a writer (two 1280x1024 gray cameras: ~84 MB).
  int queue_sets = 32;
  int writer_threads = 2;
  // Live cameras: a full queue drops the set. Replay sources (false): Submit
  // waits for room instead, as a recording can wait.
  bool drop_when_full = true;
  // When the queue is a quarter full or more, write at PNG level 0 (stored:
  // ~1 ms per frame instead of ~15, still lossless, larger files) until it
  // drains: the encoder then keeps up whenever the disk does. Counted in
  // fast_sets().
  bool adaptive = true;
  // Test hook: each writer sleeps this long per set (a slow disk).
  double writer_delay_s = 0.0;
};

class AsyncRecorder {
 public:
  // `recorder` must be open and outlive this object; it is used only by
  // the writer threads until Stop returns.
  AsyncRecorder(SessionRecorder* recorder, AsyncRecorderOptions options = {});
  ~AsyncRecorder();  // Stop()
  AsyncRecorder(const AsyncRecorder&) = delete;
  AsyncRecorder& operator=(const AsyncRecorder&) = delete;

  // Queues the set (moved) with its joint values (NaN = none). False when
  // the queue is full (the set is dropped and counted) or after a failure
  // (see failed()). Never waits for a writer.
  bool Submit(FrameSet set, std::vector<double> joints = {});
  // Waits until every queued set is written and committed, then joins the
  // writers. The first write failure, or Ok.
  Status Stop();

  bool failed() const;
  int64_t submitted() const;
  int64_t dropped_sets() const;  // queue full
  int max_queue_depth() const;
  int64_t fast_sets() const;  // written at level 0 by `adaptive`

 private:
  struct Job {
    int64_t frame = 0;
    FrameSet set;
    std::vector<double> joints;
  };
  struct Done {
    FrameSet set;  // timestamps and sequences only (images released)
    std::vector<double> joints;
    uint64_t bytes = 0;
  };
  void WriterLoop();
  void CommitReady();  // with mu_ held

  SessionRecorder* recorder_;
  AsyncRecorderOptions options_;
  mutable std::mutex mu_;
  std::condition_variable work_;
  std::condition_variable space_;
  std::deque<Job> queue_;
  std::map<int64_t, Done> done_;  // written, waiting for earlier frames
  std::vector<std::thread> writers_;
  int64_t next_frame_ = 0;
  int64_t submitted_ = 0;
  int64_t dropped_ = 0;
  int max_depth_ = 0;
  int64_t fast_ = 0;
  bool stopping_ = false;
  bool stopped_ = false;
  Status error_;
};

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_ASYNC_RECORDER_H_
