#ifndef KINCAL_DATA_WARNINGS_H_
#define KINCAL_DATA_WARNINGS_H_

// Warnings: inputs that parse but look wrong (units, limits, clock agreement,
// ...). A command fills one Warnings list; in text mode each warning goes to
// stderr as it is found, in JSON mode the list becomes the result's
// `warnings` array of {code, message} (only when it is not empty). A warning
// never replaces the exit-2 refusal (InputError) where the input cannot be
// right; docs/CONVENTIONS.md "Errors and output" has the rule per check.

#include <ostream>
#include <string>
#include <vector>

namespace kincal {

struct Warning {
  std::string code;     // stable, snake_case, e.g. "joint_units_radians"
  std::string message;  // what looks wrong, the likely cause and the fix
};

class Warnings {
 public:
  // Warnings are printed to `echo` (e.g. &std::cerr in text mode) as they
  // are added; nullptr keeps them silent (JSON mode).
  explicit Warnings(std::ostream* echo = nullptr) : echo_(echo) {}

  void Add(const std::string& code, const std::string& message);
  // Adds every warning of `other` (echoing them as Add does).
  void Append(const Warnings& other);

  bool empty() const { return list_.empty(); }
  const std::vector<Warning>& list() const { return list_; }
  bool Has(const std::string& code) const;

 private:
  std::ostream* echo_;
  std::vector<Warning> list_;
};

// "warning [code]: message"
std::string FormatWarning(const Warning& warning);

}  // namespace kincal

#endif  // KINCAL_DATA_WARNINGS_H_
