#ifndef KINCAL_CAPTURE_STATUS_H_
#define KINCAL_CAPTURE_STATUS_H_

#include <string>
#include <utility>

namespace kincal::capture {

// Result of a capture operation. Hardware failure is routine (a cable pulled,
// a camera busy in another program, a full disk), so capture functions return
// a Status instead of throwing; bad user input (a malformed URI) still throws
// kincal::InputError, like everywhere else in kincal.
class Status {
 public:
  enum class Kind {
    kOk,
    kNotFound,     // no such device / camera / file
    kBusy,         // device exists but another process holds it
    kTimeout,      // no frame within the timeout
    kEndOfStream,  // replay source has no more frames (not an error)
    kIoError,      // read/write/ioctl failure, disk full, broken stream
    kUnsupported,  // format, setting or backend not available
  };

  Status() = default;
  static Status Ok() { return Status(); }
  static Status Error(Kind kind, std::string message) {
    return Status(kind, std::move(message));
  }

  bool ok() const { return kind_ == Kind::kOk; }
  Kind kind() const { return kind_; }
  const std::string& message() const { return message_; }
  // "timeout: /dev/video0: no frame within 2000 ms"
  std::string ToString() const {
    if (ok()) return "ok";
    return std::string(KindName(kind_)) + ": " + message_;
  }

  static const char* KindName(Kind kind) {
    switch (kind) {
      case Kind::kOk:
        return "ok";
      case Kind::kNotFound:
        return "not found";
      case Kind::kBusy:
        return "busy";
      case Kind::kTimeout:
        return "timeout";
      case Kind::kEndOfStream:
        return "end of stream";
      case Kind::kIoError:
        return "i/o error";
      case Kind::kUnsupported:
        return "unsupported";
    }
    return "unknown";
  }

 private:
  Status(Kind kind, std::string message)
      : kind_(kind), message_(std::move(message)) {}
  Kind kind_ = Kind::kOk;
  std::string message_;
};

// Maps an errno value from open/ioctl/write to a Status kind.
Status::Kind KindFromErrno(int err);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_STATUS_H_
