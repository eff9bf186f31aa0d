#ifndef KINCAL_CAPTURE_ROBOT_LINK_H_
#define KINCAL_CAPTURE_ROBOT_LINK_H_

// The live robot link of `kincal capture --robot-listen HOST:PORT`: a TCP
// server the robot controller connects to, speaking a line protocol any
// robot language can produce (docs/LAB.md has URScript, RAPID, KRL and
// Franka clients). ASCII, one message per line ('\n', a trailing '\r' is
// ignored), fields separated by spaces; numbers in the robot file's units
// (deg | mm), time in seconds.
//
// robot -> kincal
//   HELLO <robot name> <joint> <joint> ...   first line: joint names (those
//                                            of robot.yaml, any order)
//   SETTLED <pose> <q1> ... <qn>             at pose <pose> (integer),
//                                            settled; readings in HELLO order
//   J <t> <q1> ... <qn>                      optional stream of readings on
//                                            the controller clock (logged to
//                                            SESSION/joints.csv)
//   BYE                                      the program has ended
// kincal -> robot
//   OK kincal 1                              after a valid HELLO
//   DONE <pose> <pairs>                      pairs grabbed and recorded
//   ERROR <message>                          then kincal closes the link

#include <string>
#include <vector>

#include "capture/status.h"

namespace kincal::capture {

struct RobotMessage {
  enum Kind { kHello, kSettled, kJoints, kBye };
  Kind kind = kBye;
  std::string name;                 // HELLO: robot name
  std::vector<std::string> joints;  // HELLO: joint names
  long pose = 0;                    // SETTLED
  double t = 0;                     // J
  std::vector<double> values;       // SETTLED, J
};

// Parses one line; false with `error` for a malformed line (unknown verb,
// wrong field count for `num_joints` (ignored when < 0), a bad number).
bool ParseRobotMessage(const std::string& line, int num_joints,
                       RobotMessage* message, std::string* error);

class RobotLink;

// Reads the robot's first line and checks it is a HELLO naming exactly the
// joints `names` (any order). On success `order` maps HELLO positions to
// indices in `names`. A bad HELLO is answered with ERROR and returned as
// kUnsupported (bad input); link faults keep their kind. `robot_file` is
// used in messages.
Status ReceiveHello(RobotLink* link, const std::vector<std::string>& names,
                    const std::string& robot_file, double timeout_s,
                    std::vector<int>* order, std::string* robot_name);

// One TCP listening socket and, after Accept, one connection. Not
// thread-safe. Every call returns a Status (kTimeout, kEndOfStream when the
// peer closed, kIoError), never throws.
class RobotLink {
 public:
  RobotLink() = default;
  ~RobotLink();
  RobotLink(const RobotLink&) = delete;
  RobotLink& operator=(const RobotLink&) = delete;

  // "HOST:PORT" (HOST an IPv4 address or "localhost"; PORT 0 = any free
  // port, see port()).
  Status Listen(const std::string& host_port);
  int port() const { return port_; }
  Status Accept(double timeout_s);
  // The next line without its end; kEndOfStream when the peer closed the
  // link (a partial last line is returned first as a line).
  Status ReadLine(double timeout_s, std::string* line);
  Status WriteLine(const std::string& line);
  void Close();

 private:
  int listen_fd_ = -1;
  int fd_ = -1;
  int port_ = 0;
  std::string buffer_;
  bool peer_closed_ = false;
};

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_ROBOT_LINK_H_
