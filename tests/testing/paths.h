#ifndef KINCAL_TESTS_TESTING_PATHS_H_
#define KINCAL_TESTS_TESTING_PATHS_H_

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <string>

namespace kincal::testing {

// Root of the source tree (bundled robot files live in data/robots).
inline std::string SourceDir() { return KINCAL_SOURCE_DIR; }

// ../shared/data next to the project root, or $KINCAL_SHARED_DATA.
inline std::string SharedDataDir() {
  if (const char* env = std::getenv("KINCAL_SHARED_DATA")) return env;
  return KINCAL_SHARED_DATA_DIR;
}

inline bool Exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

// The built kincal binary.
inline std::string KincalBinary() {
  return std::string(KINCAL_BIN_DIR) + "/kincal";
}

// A fresh temporary folder for one test (removed by the OS, not by the test).
inline std::string MakeTempDir(const std::string& tag) {
  std::string templ = ::testing::TempDir() + "kincal_" + tag + "_XXXXXX";
  char* dir = ::mkdtemp(templ.data());
  return dir ? std::string(dir) : std::string();
}

}  // namespace kincal::testing

// Skips the current test with a clear message when a shared data folder is
// absent (as on a user's machine without ../shared).
#define KINCAL_REQUIRE_SHARED_DATA(subdir)                           \
  do {                                                               \
    const std::string kincal_dir =                                   \
        ::kincal::testing::SharedDataDir() + "/" + (subdir);         \
    if (!::kincal::testing::Exists(kincal_dir)) {                    \
      GTEST_SKIP() << "shared real data not found at " << kincal_dir \
                   << " (set KINCAL_SHARED_DATA to ../shared/data)"; \
    }                                                                \
  } while (0)

#endif  // KINCAL_TESTS_TESTING_PATHS_H_
