#include "capture/async_recorder.h"

#include <chrono>

namespace kincal::capture {

AsyncRecorder::AsyncRecorder(SessionRecorder* recorder,
                             AsyncRecorderOptions options)
    : recorder_(recorder), options_(options) {
  next_frame_ = recorder_->frames();
  const int threads = std::max(1, options_.writer_threads);
  for (int i = 0; i < threads; ++i) {
    writers_.emplace_back([this] { WriterLoop(); });
  }
}

AsyncRecorder::~AsyncRecorder() { Stop(); }

bool AsyncRecorder::Submit(FrameSet set, std::vector<double> joints) {
  std::unique_lock<std::mutex> lock(mu_);
  ++submitted_;
  const size_t capacity = std::max(1, options_.queue_sets);
  if (!options_.drop_when_full) {
    space_.wait(lock, [&] {
      return queue_.size() < capacity || !error_.ok() || stopping_;
    });
  }
  if (!error_.ok() || stopping_) return false;
  if (queue_.size() >= capacity) {
    ++dropped_;
    return false;
  }
  Status check = recorder_->CheckWrite(next_frame_, joints);
  if (check.ok()) check = recorder_->CheckSet(next_frame_, set);
  if (!check.ok()) {
    error_ = check;
    return false;
  }
  queue_.push_back(Job{next_frame_++, std::move(set), std::move(joints)});
  max_depth_ = std::max(max_depth_, static_cast<int>(queue_.size()));
  work_.notify_one();
  return true;
}

void AsyncRecorder::WriterLoop() {
  for (;;) {
    Job job;
    bool fast = false;
    {
      std::unique_lock<std::mutex> lock(mu_);
      work_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping and drained
      job = std::move(queue_.front());
      queue_.pop_front();
      fast = options_.adaptive &&
             4 * static_cast<int>(queue_.size()) >= options_.queue_sets;
      if (fast) ++fast_;
      space_.notify_one();
      if (!error_.ok()) continue;  // discard after a failure
    }
    if (options_.writer_delay_s > 0) {
      std::this_thread::sleep_for(
          std::chrono::duration<double>(options_.writer_delay_s));
    }
    uint64_t bytes = 0;
    const Status s =
        recorder_->WriteSetImages(job.frame, job.set, &bytes, fast ? 0 : -1);
    std::lock_guard<std::mutex> lock(mu_);
    if (!s.ok()) {
      if (error_.ok()) error_ = s;
      space_.notify_all();
      continue;
    }
    Done done;
    done.set.frames.resize(job.set.frames.size());
    for (size_t c = 0; c < job.set.frames.size(); ++c) {
      done.set.frames[c].timestamp_s = job.set.frames[c].timestamp_s;
      done.set.frames[c].sequence = job.set.frames[c].sequence;
    }
    done.set.index = job.set.index;
    done.joints = std::move(job.joints);
    done.bytes = bytes;
    done_.emplace(job.frame, std::move(done));
    CommitReady();
  }
}

void AsyncRecorder::CommitReady() {
  // Rows are committed in frame order, and only while no frame has failed:
  // a failed frame is a gap that later frames may not cross.
  while (error_.ok()) {
    auto it = done_.find(recorder_->frames());
    if (it == done_.end()) return;
    const Status s = recorder_->CommitRow(it->second.set, it->second.joints,
                                          it->second.bytes);
    done_.erase(it);
    if (!s.ok()) {
      error_ = s;
      space_.notify_all();
    }
  }
}

Status AsyncRecorder::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopped_) return error_;
    stopping_ = true;
  }
  work_.notify_all();
  space_.notify_all();
  for (std::thread& t : writers_) t.join();
  writers_.clear();
  std::lock_guard<std::mutex> lock(mu_);
  stopped_ = true;
  // Frames written after a failed one are not in the journal: remove them.
  for (const auto& [frame, done] : done_) recorder_->RemoveSetImages(frame);
  done_.clear();
  return error_;
}

bool AsyncRecorder::failed() const {
  std::lock_guard<std::mutex> lock(mu_);
  return !error_.ok();
}
int64_t AsyncRecorder::submitted() const {
  std::lock_guard<std::mutex> lock(mu_);
  return submitted_;
}
int64_t AsyncRecorder::dropped_sets() const {
  std::lock_guard<std::mutex> lock(mu_);
  return dropped_;
}
int64_t AsyncRecorder::fast_sets() const {
  std::lock_guard<std::mutex> lock(mu_);
  return fast_;
}
int AsyncRecorder::max_queue_depth() const {
  std::lock_guard<std::mutex> lock(mu_);
  return max_depth_;
}

}  // namespace kincal::capture
