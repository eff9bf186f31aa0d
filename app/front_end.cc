// bin/kincal's side of the image commands (app/front_end.h): their entries in
// the command list, and the exec into kincal-vision. Built into bin/kincal
// only; bin/kincal-vision has the real commands (cmd_camcal.cc, ...).
//
// The descriptions are app/front_end.h's, shared with cmd_<name>.cc
// (tests/startup_cli_test.cc compares both executables' --help).

#include "app/front_end.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "app/command.h"

namespace kincal::app {
namespace {

std::string ThisExecutable() {
  std::vector<char> buf(4096);
  const ssize_t n = readlink("/proc/self/exe", buf.data(), buf.size() - 1);
  return n > 0 ? std::string(buf.data(), static_cast<size_t>(n)) : "";
}

std::string ImageBinary() {
  if (const char* env = std::getenv("KINCAL_VISION"); env && *env) return env;
  const std::string self = ThisExecutable();
  const std::string dir = self.substr(0, self.find_last_of('/') + 1);
  for (const std::string& candidate :
       {dir + "kincal-vision", dir + "../libexec/kincal/kincal-vision"}) {
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return dir + "kincal-vision";  // for the message
}

// An image command: listed with its description; whatever follows its name
// (including --help) is kincal-vision's to parse.
void AddImageCommand(CLI::App& app, Runner* run, const std::string& name,
                     const std::string& description) {
  CLI::App* sub = app.add_subcommand(name, description);
  sub->set_help_flag();  // `kincal NAME --help` is kincal-vision's help
  sub->allow_extras();
  sub->callback([run] { *run = [] { return ExecImageBinary(); }; });
}

}  // namespace

int ExecImageBinary() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string cmdline((std::istreambuf_iterator<char>(in)),
                            std::istreambuf_iterator<char>());
  std::vector<std::string> args;
  for (size_t start = 0; start < cmdline.size();) {
    const size_t end = cmdline.find('\0', start);
    args.push_back(cmdline.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string path = ImageBinary();
  std::cout.flush();
  execv(path.c_str(), argv.data());
  std::cerr << "kincal: failure: this command runs in " << path
            << ", which cannot be started (" << std::strerror(errno)
            << "): an incomplete installation (build the kincal target, or "
               "set KINCAL_VISION)\n";
  return 1;
}

// AddCamcalCommand, AddTrackCommand, ...: one per name in
// KINCAL_IMAGE_COMMANDS (app/CMakeLists.txt), each listed with its
// k<Name>Description.
#define KINCAL_IMAGE_COMMAND(name, Name)                    \
  void Add##Name##Command(CLI::App& app, Runner* run) {     \
    AddImageCommand(app, run, #name, k##Name##Description); \
  }
#include "app/image_commands.inc"
#undef KINCAL_IMAGE_COMMAND

}  // namespace kincal::app
