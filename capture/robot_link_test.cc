#include "capture/robot_link.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <thread>

namespace kincal::capture {
namespace {

TEST(RobotLinkTest, ParsesTheProtocol) {
  RobotMessage m;
  std::string error;
  ASSERT_TRUE(ParseRobotMessage("HELLO ur10 a b c", -1, &m, &error));
  EXPECT_EQ(m.kind, RobotMessage::kHello);
  EXPECT_EQ(m.name, "ur10");
  EXPECT_EQ(m.joints, (std::vector<std::string>{"a", "b", "c"}));
  ASSERT_TRUE(ParseRobotMessage("SETTLED 7 1.5 -2e1", 2, &m, &error));
  EXPECT_EQ(m.kind, RobotMessage::kSettled);
  EXPECT_EQ(m.pose, 7);
  EXPECT_EQ(m.values, (std::vector<double>{1.5, -20.0}));
  ASSERT_TRUE(ParseRobotMessage("J 100.25 1 2", 2, &m, &error));
  EXPECT_DOUBLE_EQ(m.t, 100.25);
  ASSERT_TRUE(ParseRobotMessage("BYE", 2, &m, &error));
  EXPECT_EQ(m.kind, RobotMessage::kBye);
  for (const char* bad : {"", "HELLO x", "SETTLED", "SETTLED x 1 2",
                          "SETTLED 1 1", "SETTLED 1 1 2 3", "SETTLED 1 1 nan",
                          "J 1 2", "J t 1 2", "BYE now", "MOVE 1 2"}) {
    EXPECT_FALSE(ParseRobotMessage(bad, 2, &m, &error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
}

TEST(RobotLinkTest, LinesOverLoopbackWithPartialWritesAndCrLf) {
  RobotLink link;
  ASSERT_TRUE(link.Listen("127.0.0.1:0").ok());
  ASSERT_GT(link.port(), 0);
  std::thread client([port = link.port()] {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
    for (const char* part : {"HEL", "LO r a\r\nSETT", "LED 1 2\nlast"}) {
      ::send(fd, part, std::strlen(part), 0);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    char buf[64];
    const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
    EXPECT_EQ(std::string(buf, n > 0 ? n : 0), "OK\n");
    ::close(fd);
  });
  ASSERT_TRUE(link.Accept(5).ok());
  std::string line;
  ASSERT_TRUE(link.ReadLine(5, &line).ok());
  EXPECT_EQ(line, "HELLO r a");
  ASSERT_TRUE(link.ReadLine(5, &line).ok());
  EXPECT_EQ(line, "SETTLED 1 2");
  ASSERT_TRUE(link.WriteLine("OK").ok());
  ASSERT_TRUE(link.ReadLine(5, &line).ok());  // the unterminated last line
  EXPECT_EQ(line, "last");
  EXPECT_EQ(link.ReadLine(5, &line).kind(), Status::Kind::kEndOfStream);
  client.join();
}

TEST(RobotLinkTest, TimeoutsAndBadAddresses) {
  RobotLink link;
  EXPECT_EQ(link.Listen("nonsense").kind(), Status::Kind::kUnsupported);
  RobotLink other;
  ASSERT_TRUE(other.Listen("localhost:0").ok());
  EXPECT_EQ(other.Accept(0.05).kind(), Status::Kind::kTimeout);
}

}  // namespace
}  // namespace kincal::capture
