// libFuzzer target: a recorded session's frames.csv (ParseSessionFramesCsv),
// read as a finished and as an unfinished session, with and without the
// robot's joint names. Any input must end in a value or an InputError (the
// CLI's exit 2); anything else (a crash, a sanitizer report, another
// exception type, a hang) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "data/error.h"
#include "data/session.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  kincal::SessionReadOptions with_joints;
  with_joints.joint_names = {"j1", "j2", "j3", "j4", "j5"};
  kincal::SessionReadOptions none;
  for (const kincal::SessionReadOptions* options : {&none, &with_joints}) {
    for (bool partial : {false, true}) {
      kincal::Session session;
      try {
        kincal::ParseSessionFramesCsv(text, "frames.csv", *options, partial,
                                      &session);
      } catch (const kincal::InputError&) {
      }
    }
  }
  return 0;
}
