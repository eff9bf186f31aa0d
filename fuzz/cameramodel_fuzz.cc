// libFuzzer target: mrcal's .cameramodel (ParseCameraModel). Any input must
// end in a value or an InputError (the CLI's exit 2); anything else (a
// crash, a sanitizer report, another exception type, a hang) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "camcal/cameramodel.h"
#include "data/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    kincal::ParseCameraModel(text, "camera.cameramodel");
  } catch (const kincal::InputError&) {
  }
  return 0;
}
