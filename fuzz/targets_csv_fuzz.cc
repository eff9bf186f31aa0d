// libFuzzer target: compensate's targets file (ParseTargetsCsv). Any input
// must end in a value or an InputError (the CLI's exit 2); anything else (a
// crash, a sanitizer report, another exception type, a hang) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "data/error.h"
#include "data/targets_csv.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    kincal::ParseTargetsCsv(text, "targets.csv",
                            {"j1", "j2", "j3", "j4", "j5", "j6"});
  } catch (const kincal::InputError&) {
  }
  return 0;
}
