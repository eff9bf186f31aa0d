#ifndef KINCAL_CAPTURE_JOINT_STREAM_H_
#define KINCAL_CAPTURE_JOINT_STREAM_H_

// The live joint stream of `kincal capture --robot-listen ... --stream`:
// while the cameras record, a thread reads the robot's `J <t> <q...>` lines
// (capture/robot_link.h), stamping each with the host monotonic time it
// arrived. The controller clock is put on the host clock by the smallest
// observed (arrival - t): the sample that travelled fastest, so the offset
// is late by at most that sample's latency (LAN: about a millisecond).

#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "capture/joint_log.h"
#include "capture/robot_link.h"

namespace kincal::capture {

class JointStreamReceiver {
 public:
  // `link` is connected and past HELLO; `order` maps HELLO positions to
  // joint indices (ReceiveHello). Not owned; must outlive Stop.
  JointStreamReceiver(RobotLink* link, std::vector<int> order,
                      std::vector<std::string> names);
  ~JointStreamReceiver();  // Stop()
  void Start();
  void Stop();

  // True once the robot said BYE, or the link failed (see status()).
  bool finished() const;
  // Ok, kUnsupported for a malformed line (bad input), the link's error
  // when it dropped without BYE.
  Status status() const;
  size_t samples() const;

  // After Stop: the readings as a joint log on the controller clock, and
  // the offset to the host clock (t_host = t + offset). InputError when
  // fewer than two readings came.
  JointLog Log() const;
  double OffsetToHost() const;

 private:
  void Loop();

  RobotLink* link_;
  std::vector<int> order_;
  std::vector<std::string> names_;
  std::thread thread_;
  mutable std::mutex mu_;
  bool stop_ = false, finished_ = false;
  Status status_;
  std::vector<double> t_, arrival_;
  std::vector<std::vector<double>> q_;
};

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_JOINT_STREAM_H_
