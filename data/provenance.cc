#include "data/provenance.h"

namespace kincal {
namespace {
std::string& Storage() {
  static std::string command = "kincal (library call)";
  return command;
}

std::string Quote(const std::string& arg) {
  if (!arg.empty() && arg.find_first_of(" \t\"'*?$\\") == std::string::npos)
    return arg;
  std::string out = "'";
  for (char c : arg) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}
}  // namespace

void SetCommandLine(int argc, const char* const* argv) {
  std::string command;
  for (int i = 0; i < argc; ++i) {
    if (i > 0) command += ' ';
    command += i == 0 ? std::string("kincal") : Quote(argv[i]);
  }
  Storage() = command;
}

void SetCommandLine(const std::string& command) { Storage() = command; }

const std::string& CommandLine() { return Storage(); }

std::string ToolVersion() { return "kincal 0.1.0"; }

}  // namespace kincal
