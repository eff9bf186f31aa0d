#ifndef KINCAL_DATA_ERROR_H_
#define KINCAL_DATA_ERROR_H_

#include <sstream>
#include <stdexcept>
#include <string>

namespace kincal {

// Bad input: a file, option or data set that the user must fix. The CLI prints
// what() and exits with code 2, writing nothing. `line` and `column` are
// 1-based; 0 means "not applicable" (e.g. a whole-file problem).
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, int line, int column,
             const std::string& message)
      : std::runtime_error(Format(file, line, column, message)),
        file_(file),
        line_(line),
        column_(column) {}
  explicit InputError(const std::string& message)
      : std::runtime_error(message), line_(0), column_(0) {}

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  static std::string Format(const std::string& file, int line, int column,
                            const std::string& message) {
    std::ostringstream os;
    os << file;
    if (line > 0) os << ":" << line;
    if (column > 0) os << ":" << column;
    os << ": " << message;
    return os.str();
  }
  std::string file_;
  int line_;
  int column_;
};

// Raises InputError(message) unless `condition` holds. For validating user
// input; programming errors use KINCAL_CHECK below.
inline void Require(bool condition, const std::string& message) {
  if (!condition) throw InputError(message);
}

}  // namespace kincal

// Internal invariant check that stays on in release builds (not an assert).
#define KINCAL_CHECK(cond, msg)                                      \
  do {                                                               \
    if (!(cond)) {                                                   \
      std::ostringstream kincal_check_os;                            \
      kincal_check_os << __FILE__ << ":" << __LINE__                 \
                      << ": check failed: " << #cond << ": " << msg; \
      throw std::logic_error(kincal_check_os.str());                 \
    }                                                                \
  } while (0)

#endif  // KINCAL_DATA_ERROR_H_
