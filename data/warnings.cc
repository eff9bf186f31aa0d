#include "data/warnings.h"

namespace kincal {

std::string FormatWarning(const Warning& warning) {
  return "warning [" + warning.code + "]: " + warning.message;
}

void Warnings::Add(const std::string& code, const std::string& message) {
  list_.push_back({code, message});
  if (echo_ != nullptr) *echo_ << FormatWarning(list_.back()) << "\n";
}

void Warnings::Append(const Warnings& other) {
  for (const Warning& w : other.list()) Add(w.code, w.message);
}

bool Warnings::Has(const std::string& code) const {
  for (const Warning& w : list_) {
    if (w.code == code) return true;
  }
  return false;
}

}  // namespace kincal
