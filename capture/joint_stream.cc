#include "capture/joint_stream.h"

#include <algorithm>
#include <limits>

#include "capture/frame_source.h"
#include "data/error.h"

namespace kincal::capture {

JointStreamReceiver::JointStreamReceiver(RobotLink* link,
                                         std::vector<int> order,
                                         std::vector<std::string> names)
    : link_(link), order_(std::move(order)), names_(std::move(names)) {}

JointStreamReceiver::~JointStreamReceiver() { Stop(); }

void JointStreamReceiver::Start() {
  thread_ = std::thread([this] { Loop(); });
}

void JointStreamReceiver::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  if (thread_.joinable()) thread_.join();
}

void JointStreamReceiver::Loop() {
  int line_number = 1;
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (stop_) return;
    }
    std::string line;
    const Status s = link_->ReadLine(0.25, &line);
    const double arrival = MonotonicSeconds();
    if (s.kind() == Status::Kind::kTimeout) continue;
    std::lock_guard<std::mutex> lock(mu_);
    if (!s.ok()) {
      status_ = Status::Error(
          s.kind() == Status::Kind::kEndOfStream ? Status::Kind::kIoError
                                                 : s.kind(),
          "robot link lost after " + std::to_string(t_.size()) +
              " joint readings, without BYE: " + s.message());
      finished_ = true;
      return;
    }
    ++line_number;
    RobotMessage m;
    std::string error;
    if (!ParseRobotMessage(line, static_cast<int>(names_.size()), &m, &error) ||
        (m.kind != RobotMessage::kJoints && m.kind != RobotMessage::kBye) ||
        (m.kind == RobotMessage::kJoints && !t_.empty() && m.t <= t_.back())) {
      if (error.empty()) {
        error = m.kind == RobotMessage::kJoints
                    ? "time " + std::to_string(m.t) +
                          " does not increase (controller clock jump?)"
                    : "only J and BYE lines in --stream mode";
      }
      status_ =
          Status::Error(Status::Kind::kUnsupported,
                        "robot link, line " + std::to_string(line_number) +
                            " '" + line + "': " + error);
      link_->WriteLine("ERROR " + error);
      finished_ = true;
      return;
    }
    if (m.kind == RobotMessage::kBye) {
      finished_ = true;
      return;
    }
    std::vector<double> q(names_.size());
    for (size_t k = 0; k < order_.size(); ++k) q[order_[k]] = m.values[k];
    t_.push_back(m.t);
    arrival_.push_back(arrival);
    q_.push_back(std::move(q));
  }
}

bool JointStreamReceiver::finished() const {
  std::lock_guard<std::mutex> lock(mu_);
  return finished_;
}
Status JointStreamReceiver::status() const {
  std::lock_guard<std::mutex> lock(mu_);
  return status_;
}
size_t JointStreamReceiver::samples() const {
  std::lock_guard<std::mutex> lock(mu_);
  return t_.size();
}

JointLog JointStreamReceiver::Log() const {
  std::lock_guard<std::mutex> lock(mu_);
  if (t_.size() < 2) {
    throw InputError("robot link: " + std::to_string(t_.size()) +
                     " joint readings (J lines) came; at least two are "
                     "needed to fill the frames");
  }
  JointLog log;
  log.source = "robot link";
  log.names = names_;
  log.t = t_;
  log.q = q_;
  return log;
}

double JointStreamReceiver::OffsetToHost() const {
  std::lock_guard<std::mutex> lock(mu_);
  double offset = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < t_.size(); ++i) {
    offset = std::min(offset, arrival_[i] - t_[i]);
  }
  return offset;
}

}  // namespace kincal::capture
