#ifndef KINCAL_TESTS_TESTING_RUN_H_
#define KINCAL_TESTS_TESTING_RUN_H_

// Runs the built kincal binary for end-to-end tests: exit code, stdout and
// stderr (stderr through a temporary file).

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/testing/paths.h"

namespace kincal::testing {

struct RunResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Runs `command` through /bin/sh.
inline RunResult RunShell(const std::string& command) {
  RunResult r;
  const std::string err_path = MakeTempDir("stderr") + "/stderr.txt";
  const std::string full = command + " 2>" + err_path;
  FILE* pipe = ::popen(full.c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) {
    r.out.append(buf.data(), n);
  }
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err(err_path);
  std::stringstream ss;
  ss << err.rdbuf();
  r.err = ss.str();
  return r;
}

// Runs build/bin/kincal with `args` (already shell-quoted where needed).
inline RunResult RunKincal(const std::string& args) {
  return RunShell(KincalBinary() + " " + args);
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TESTING_RUN_H_
