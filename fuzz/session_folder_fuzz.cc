// libFuzzer target: a whole recorded-session folder (ReadSession: session.yaml,
// frames.csv or frames.csv.part, left/ and right/ image names). The input is
// up to five sections separated by NUL bytes:
//   session.yaml \0 frames.csv \0 left names \0 right names \0 options
// (names one per line; options: 'p' = frames.csv.part instead of frames.csv,
// 'j' = the robot's joints j1..j5 are required as columns, 'r' = joint
// readings are required). A missing section means a missing file/folder.
// The files are written into a private temporary folder for each input
// (images are empty files: ReadSession locates images, it does not decode
// them). Any input must end in a value or an InputError (the CLI's exit 2);
// anything else (a crash, a sanitizer report, another exception type, a
// hang) is a finding.
#include <unistd.h>

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "data/error.h"
#include "data/session.h"

namespace {

namespace fs = std::filesystem;

std::vector<std::string> Split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (;;) {
    const size_t end = text.find(sep, start);
    parts.push_back(text.substr(start, end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

void Write(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Image names from one line each: only [A-Za-z0-9._-], no '.'/'..', at most
// 16 names of at most 40 characters (the folder listing is what is fuzzed,
// not the file system).
void MakeImages(const fs::path& folder, const std::string& names) {
  fs::create_directory(folder);
  int n = 0;
  for (const std::string& line : Split(names, '\n')) {
    std::string name;
    for (char c : line) {
      if (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' ||
          c == '-') {
        name += c;
      }
    }
    if (name.empty() || name == "." || name == ".." || name.size() > 40)
      continue;
    Write(folder / name, "");
    if (++n == 16) break;
  }
}

// A private temporary folder, removed at exit (the path is never destroyed,
// so the exit handler can still read it).
const fs::path& Root() {
  static const fs::path* root = [] {
    std::string tmpl =
        (fs::temp_directory_path() / "kincal_fuzz_session_XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) std::abort();
    auto* path = new fs::path(tmpl);
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(Root(), ec);
    });
    return path;
  }();
  return *root;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts =
      Split(std::string(reinterpret_cast<const char*>(data), size), '\0');
  const fs::path dir = Root() / "s";
  fs::remove_all(dir);
  fs::create_directory(dir);
  const std::string options = parts.size() > 4 ? parts[4] : "";
  Write(dir / "session.yaml", parts[0]);
  if (parts.size() > 1) {
    const bool journal = options.find('p') != std::string::npos;
    Write(dir / (journal ? "frames.csv.part" : "frames.csv"), parts[1]);
  }
  if (parts.size() > 2) MakeImages(dir / "left", parts[2]);
  if (parts.size() > 3) MakeImages(dir / "right", parts[3]);
  kincal::SessionReadOptions read_options;
  if (options.find('j') != std::string::npos)
    read_options.joint_names = {"j1", "j2", "j3", "j4", "j5"};
  read_options.require_joint_readings = options.find('r') != std::string::npos;
  // KINCAL_FUZZ_VERBOSE=1 prints what each input read to (to check seeds).
  static const bool verbose = std::getenv("KINCAL_FUZZ_VERBOSE") != nullptr;
  try {
    const kincal::Session s = kincal::ReadSession(dir.string(), read_options);
    if (verbose) {
      std::printf("read: status %s, %zu frames, %d with joints, %d dropped\n",
                  s.status.c_str(), s.frames.size(), s.CountWithJoints(),
                  s.dropped_tail);
    }
  } catch (const kincal::InputError& e) {
    if (verbose) std::printf("InputError: %s\n", e.what());
  }
  return 0;
}
