#include "data/glob.h"

#include <glob.h>

#include <algorithm>

#include "data/error.h"

namespace kincal {

std::vector<std::string> GlobSorted(const std::string& pattern) {
  glob_t g{};
  std::vector<std::string> files;
  if (::glob(pattern.c_str(), 0, nullptr, &g) == 0) {
    for (size_t i = 0; i < g.gl_pathc; ++i) files.emplace_back(g.gl_pathv[i]);
  }
  ::globfree(&g);
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> GlobSortedOrThrow(const std::string& pattern,
                                           const std::string& option) {
  std::vector<std::string> files = GlobSorted(pattern);
  if (files.empty()) {
    throw InputError(option + " '" + pattern + "': no file matches");
  }
  return files;
}

}  // namespace kincal
