// Tests of atomic writes and whole-file reads (data/atomic_file.cc).

#include "data/atomic_file.h"

#include <dirent.h>
#include <gtest/gtest.h>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::kincal::testing::MakeTempDir;

int FilesIn(const std::string& dir) {
  int n = 0;
  DIR* d = ::opendir(dir.c_str());
  while (dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    n += name != "." && name != "..";
  }
  ::closedir(d);
  return n;
}

TEST(AtomicFileTest, WriteReplacesTheFileAndLeavesNoTemporary) {
  const std::string dir = MakeTempDir("atomic");
  const std::string path = dir + "/out.csv";
  WriteFileAtomic(path, "first\n");
  EXPECT_EQ(ReadFile(path), "first\n");
  const std::string binary("a\0b\r\n", 5);
  WriteFileAtomic(path, binary);
  EXPECT_EQ(ReadFile(path), binary);
  EXPECT_EQ(FilesIn(dir), 1);
}

TEST(AtomicFileTest, UnwritableFolderIsAnInputErrorNamingThePath) {
  const std::string path = MakeTempDir("atomic_bad") + "/missing/out.csv";
  try {
    WriteFileAtomic(path, "x");
    FAIL() << "wrote into a missing folder";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("cannot write"), std::string::npos)
        << e.what();
  }
}

TEST(AtomicFileTest, ReadingAMissingFileIsAnInputError) {
  const std::string path = MakeTempDir("atomic_read") + "/none.yaml";
  try {
    ReadFile(path);
    FAIL() << "read a missing file";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path +
                                         ": cannot open: No such file or "
                                         "directory");
  }
}

}  // namespace
}  // namespace kincal
