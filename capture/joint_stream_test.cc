// Tests of the live joint stream (capture/joint_stream.cc) over loopback.

#include "capture/joint_stream.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <thread>

#include "capture/frame_source.h"
#include "data/error.h"
#include "tests/testing/loopback.h"

namespace kincal::capture {
namespace {

using ::kincal::testing::ConnectLoopback;
using ::kincal::testing::SendLine;

// The robot's side: connects to `port`, sends `lines`, closes the link.
std::thread RobotSends(int port, std::vector<std::string> lines) {
  return std::thread([port, lines] {
    const int fd = ConnectLoopback(port, 100);
    if (fd < 0) return;
    for (const std::string& line : lines) SendLine(fd, line);
    ::close(fd);
  });
}

// Listens, lets the robot send `lines` and starts a receiver on the link.
std::unique_ptr<JointStreamReceiver> Receive(
    RobotLink* link, const std::vector<std::string>& lines,
    const std::vector<int>& order) {
  if (!link->Listen("127.0.0.1:0").ok()) return nullptr;
  std::thread robot = RobotSends(link->port(), lines);
  const bool accepted = link->Accept(5).ok();
  robot.join();
  if (!accepted) return nullptr;
  auto receiver = std::make_unique<JointStreamReceiver>(
      link, order, std::vector<std::string>{"a", "b"});
  receiver->Start();
  return receiver;
}

bool WaitFinished(const JointStreamReceiver& receiver) {
  for (int i = 0; i < 200 && !receiver.finished(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return receiver.finished();
}

TEST(JointStreamTest, ReadingsInRobotOrderOnTheControllerClockUntilBye) {
  RobotLink link;
  const double before = MonotonicSeconds();
  // HELLO listed b before a: position 0 is joint 1.
  auto receiver = Receive(&link, {"J 1.0 10 20", "J 1.5 11 21", "BYE"}, {1, 0});
  ASSERT_TRUE(receiver);
  ASSERT_TRUE(WaitFinished(*receiver));
  receiver->Stop();
  const double after = MonotonicSeconds();
  EXPECT_TRUE(receiver->status().ok()) << receiver->status().ToString();
  EXPECT_EQ(receiver->samples(), 2u);
  const JointLog log = receiver->Log();
  ASSERT_EQ(log.t.size(), 2u);
  EXPECT_DOUBLE_EQ(log.t[0], 1.0);
  EXPECT_DOUBLE_EQ(log.t[1], 1.5);
  EXPECT_EQ(log.names, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(log.q[0], (std::vector<double>{20, 10}));
  EXPECT_EQ(log.q[1], (std::vector<double>{21, 11}));
  // t_host = t + offset: the fastest sample arrived between before and
  // after, so the offset lies within them minus its controller time.
  const double offset = receiver->OffsetToHost();
  EXPECT_GE(offset, before - 1.5);
  EXPECT_LE(offset, after - 1.0);
}

TEST(JointStreamTest, AMalformedLineIsBadInput) {
  RobotLink link;
  auto receiver = Receive(&link, {"J 1.0 10 20", "SETTLED 1 10 20"}, {0, 1});
  ASSERT_TRUE(receiver);
  ASSERT_TRUE(WaitFinished(*receiver));
  receiver->Stop();
  EXPECT_EQ(receiver->status().kind(), Status::Kind::kUnsupported)
      << receiver->status().ToString();
  EXPECT_NE(receiver->status().message().find("only J and BYE"),
            std::string::npos)
      << receiver->status().message();
}

TEST(JointStreamTest, ALinkDroppedWithoutByeFailsAndOneReadingIsNoLog) {
  RobotLink link;
  auto receiver = Receive(&link, {"J 1.0 10 20"}, {0, 1});
  ASSERT_TRUE(receiver);
  ASSERT_TRUE(WaitFinished(*receiver));
  receiver->Stop();
  EXPECT_FALSE(receiver->status().ok());
  EXPECT_NE(receiver->status().kind(), Status::Kind::kUnsupported);
  EXPECT_THROW(receiver->Log(), InputError);
}

}  // namespace
}  // namespace kincal::capture
