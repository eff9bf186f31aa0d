#include "capture/robot_link.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <sstream>

#include "data/csv.h"

namespace kincal::capture {
namespace {

Status Io(const std::string& what) {
  return Status::Error(Status::Kind::kIoError,
                       "robot link: " + what + ": " + std::strerror(errno));
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  std::string word;
  while (in >> word) out.push_back(word);
  return out;
}

}  // namespace

bool ParseRobotMessage(const std::string& line, int num_joints,
                       RobotMessage* message, std::string* error) {
  const std::vector<std::string> w = Split(line);
  if (w.empty()) {
    *error = "empty line";
    return false;
  }
  RobotMessage m;
  auto numbers = [&](size_t from, std::vector<double>* out) {
    for (size_t i = from; i < w.size(); ++i) {
      double v = 0;
      if (!ParseFiniteDouble(w[i], &v)) {
        *error = "field " + std::to_string(i + 1) + " '" + w[i] +
                 "' is not a number";
        return false;
      }
      out->push_back(v);
    }
    if (num_joints >= 0 && static_cast<int>(out->size()) != num_joints) {
      *error = "expected " + std::to_string(num_joints) +
               " joint values, found " + std::to_string(out->size());
      return false;
    }
    return true;
  };
  if (w[0] == "HELLO") {
    if (w.size() < 3) {
      *error = "expected HELLO <robot name> <joint names...>";
      return false;
    }
    m.kind = RobotMessage::kHello;
    m.name = w[1];
    m.joints.assign(w.begin() + 2, w.end());
  } else if (w[0] == "SETTLED") {
    m.kind = RobotMessage::kSettled;
    char* end = nullptr;
    if (w.size() < 2 || (m.pose = std::strtol(w[1].c_str(), &end, 10), *end) ||
        w[1].empty()) {
      *error = "expected SETTLED <pose number> <joint values...>";
      return false;
    }
    if (!numbers(2, &m.values)) return false;
  } else if (w[0] == "J") {
    m.kind = RobotMessage::kJoints;
    if (w.size() < 2 || !ParseFiniteDouble(w[1], &m.t)) {
      *error = "expected J <t> <joint values...>";
      return false;
    }
    if (!numbers(2, &m.values)) return false;
  } else if (w[0] == "BYE") {
    if (w.size() != 1) {
      *error = "BYE takes no fields";
      return false;
    }
    m.kind = RobotMessage::kBye;
  } else {
    *error = "unknown message '" + w[0] + "' (expected HELLO, SETTLED, J, BYE)";
    return false;
  }
  *message = std::move(m);
  return true;
}

Status ReceiveHello(RobotLink* link, const std::vector<std::string>& names,
                    const std::string& robot_file, double timeout_s,
                    std::vector<int>* order, std::string* robot_name) {
  std::string line, error;
  Status s = link->ReadLine(timeout_s, &line);
  if (!s.ok()) {
    return Status::Error(s.kind(), s.message() + " (before HELLO)");
  }
  auto bad = [&](const std::string& what) {
    link->WriteLine("ERROR " + what);
    return Status::Error(Status::Kind::kUnsupported,
                         "robot link HELLO: " + what);
  };
  RobotMessage hello;
  if (!ParseRobotMessage(line, -1, &hello, &error) ||
      hello.kind != RobotMessage::kHello) {
    return bad(error.empty() ? "expected HELLO first, got '" + line + "'"
                             : error);
  }
  *robot_name = hello.name;
  order->clear();
  for (const std::string& n : hello.joints) {
    const auto it = std::find(names.begin(), names.end(), n);
    const int j = it == names.end() ? -1 : static_cast<int>(it - names.begin());
    if (j < 0 || std::find(order->begin(), order->end(), j) != order->end()) {
      std::string known;
      for (const std::string& k : names) known += " " + k;
      return bad("unknown or repeated joint '" + n + "' (" + robot_file +
                 " has:" + known + ")");
    }
    order->push_back(j);
  }
  if (order->size() != names.size()) {
    return bad("HELLO names " + std::to_string(order->size()) + " joints, " +
               robot_file + " has " + std::to_string(names.size()));
  }
  return Status::Ok();
}

RobotLink::~RobotLink() {
  Close();
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

Status RobotLink::Listen(const std::string& host_port) {
  const size_t colon = host_port.rfind(':');
  std::string host =
      colon == std::string::npos ? "" : host_port.substr(0, colon);
  const std::string port_text =
      colon == std::string::npos ? host_port : host_port.substr(colon + 1);
  if (host.empty() || host == "localhost") host = "127.0.0.1";
  char* end = nullptr;
  const long port = std::strtol(port_text.c_str(), &end, 10);
  if (port_text.empty() || *end || port < 0 || port > 65535) {
    return Status::Error(Status::Kind::kUnsupported,
                         "robot link: '" + host_port +
                             "': expected HOST:PORT, e.g. 0.0.0.0:30010");
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (::inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1) {
    return Status::Error(
        Status::Kind::kUnsupported,
        "robot link: '" + host + "' is not an IPv4 address (or localhost)");
  }
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) return Io("socket");
  const int one = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) !=
      0) {
    return Status::Error(Status::Kind::kBusy, "robot link: cannot listen on " +
                                                  host_port + ": " +
                                                  std::strerror(errno));
  }
  if (::listen(listen_fd_, 1) != 0) return Io("listen");
  socklen_t len = sizeof(addr);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  return Status::Ok();
}

Status RobotLink::Accept(double timeout_s) {
  pollfd p{listen_fd_, POLLIN, 0};
  const int r = ::poll(&p, 1, static_cast<int>(timeout_s * 1000));
  if (r == 0) {
    return Status::Error(
        Status::Kind::kTimeout,
        "robot link: no robot connected to port " + std::to_string(port_) +
            " within " + std::to_string(static_cast<int>(timeout_s)) + " s");
  }
  if (r < 0) return Io("poll");
  fd_ = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
  if (fd_ < 0) return Io("accept");
  const int one = 1;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
  buffer_.clear();
  peer_closed_ = false;
  return Status::Ok();
}

Status RobotLink::ReadLine(double timeout_s, std::string* line) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(timeout_s);
  for (;;) {
    const size_t nl = buffer_.find('\n');
    if (nl != std::string::npos) {
      *line = buffer_.substr(0, nl);
      buffer_.erase(0, nl + 1);
      if (!line->empty() && line->back() == '\r') line->pop_back();
      return Status::Ok();
    }
    if (peer_closed_) {
      if (!buffer_.empty()) {
        *line = buffer_;
        buffer_.clear();
        return Status::Ok();
      }
      return Status::Error(Status::Kind::kEndOfStream,
                           "robot link: the robot closed the connection");
    }
    if (fd_ < 0) {
      return Status::Error(Status::Kind::kIoError, "robot link: not connected");
    }
    const double left = std::chrono::duration<double>(
                            deadline - std::chrono::steady_clock::now())
                            .count();
    if (left <= 0) {
      return Status::Error(Status::Kind::kTimeout,
                           "robot link: no message from the robot for " +
                               std::to_string(static_cast<int>(timeout_s)) +
                               " s");
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(left * 1000) + 1);
    if (r < 0) {
      if (errno == EINTR) continue;
      return Io("poll");
    }
    if (r == 0) continue;
    char buf[4096];
    const ssize_t n = ::recv(fd_, buf, sizeof(buf), 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == ECONNRESET) {
        peer_closed_ = true;
        continue;
      }
      return Io("recv");
    }
    if (n == 0) {
      peer_closed_ = true;
      continue;
    }
    buffer_.append(buf, static_cast<size_t>(n));
    if (buffer_.size() > 1 << 20) {
      return Status::Error(Status::Kind::kIoError,
                           "robot link: a line longer than 1 MB");
    }
  }
}

Status RobotLink::WriteLine(const std::string& line) {
  if (fd_ < 0) {
    return Status::Error(Status::Kind::kIoError, "robot link: not connected");
  }
  const std::string data = line + "\n";
  size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n =
        ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Io("send");
    }
    sent += static_cast<size_t>(n);
  }
  return Status::Ok();
}

void RobotLink::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace kincal::capture
