#ifndef KINCAL_TESTS_TESTING_LOOPBACK_H_
#define KINCAL_TESTS_TESTING_LOOPBACK_H_

// A robot controller's side of kincal's line protocol in end-to-end tests:
// a free port on the loopback interface, a connection that waits for
// kincal to start listening, and one text line at a time.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

namespace kincal::testing {

// A port no one listens on now (bound once by the kernel, then released).
inline int FreeLoopbackPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
  socklen_t len = sizeof(a);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

// Connects to 127.0.0.1:port, trying every 50 ms up to `attempts` times
// (while kincal starts). The socket, or -1.
inline int ConnectLoopback(int port, int attempts) {
  for (int i = 0; i < attempts; ++i) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0) {
      return fd;
    }
    ::close(fd);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return -1;
}

// Sends `line` and a newline; false when the link is gone.
inline bool SendLine(int fd, const std::string& line) {
  const std::string data = line + "\n";
  return ::send(fd, data.data(), data.size(), MSG_NOSIGNAL) >= 0;
}

// Reads up to a newline (not kept); false when the link closed first.
inline bool ReceiveLine(int fd, std::string* line) {
  line->clear();
  char c;
  while (::recv(fd, &c, 1, 0) == 1) {
    if (c == '\n') return true;
    line->push_back(c);
  }
  return false;
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TESTING_LOOPBACK_H_
