// Tests of the command line recorded in outputs (data/provenance.cc).

#include "data/provenance.h"

#include <gtest/gtest.h>

namespace kincal {
namespace {

TEST(ProvenanceTest, CommandLineIsKincalWithShellQuotedArguments) {
  const char* argv[] = {"/build/bin/kincal-vision",
                        "track",
                        "--left",
                        "s/left/*.png",
                        "--out",
                        "it's here.csv",
                        ""};
  SetCommandLine(7, argv);
  EXPECT_EQ(CommandLine(),
            "kincal track --left 's/left/*.png' --out 'it'\\''s here.csv' "
            "''");
}

TEST(ProvenanceTest, SetFromTextAndVersion) {
  SetCommandLine("kincal demo");
  EXPECT_EQ(CommandLine(), "kincal demo");
  EXPECT_EQ(ToolVersion().rfind("kincal ", 0), 0u) << ToolVersion();
}

}  // namespace
}  // namespace kincal
