#ifndef KINCAL_DATA_PROVENANCE_H_
#define KINCAL_DATA_PROVENANCE_H_

#include <string>

namespace kincal {

// The command line of this run, recorded in every output ("command" in JSON,
// a "# kincal ..." comment in YAML and CSV). Set once by main().
void SetCommandLine(int argc, const char* const* argv);
void SetCommandLine(const std::string& command);
const std::string& CommandLine();

// "kincal <version>"
std::string ToolVersion();

}  // namespace kincal

#endif  // KINCAL_DATA_PROVENANCE_H_
