#ifndef KINCAL_DATA_GLOB_H_
#define KINCAL_DATA_GLOB_H_

#include <string>
#include <vector>

namespace kincal {

// Files matching a shell pattern (glob(3)), sorted by name in byte order:
// the frame order of image sequences (`kincal track`, `camcal`, replayed
// sessions). Empty when nothing matches.
std::vector<std::string> GlobSorted(const std::string& pattern);

// As GlobSorted, but bad input when nothing matches: InputError
// "<option> '<pattern>': no file matches".
std::vector<std::string> GlobSortedOrThrow(const std::string& pattern,
                                           const std::string& option);

}  // namespace kincal

#endif  // KINCAL_DATA_GLOB_H_
