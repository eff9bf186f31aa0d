#include "data/extension_kinds.h"

#include <string>

namespace kincal {

bool IsPeriodicTransmission(const Extension& e) {
  if (e.cause != "transmission") return false;
  for (int h = 1; h <= kFourierTerms / 2; ++h) {
    const std::string n = std::to_string(h);
    if (e.values.count("a" + n) > 0 || e.values.count("b" + n) > 0) {
      return true;
    }
  }
  return false;
}

}  // namespace kincal
