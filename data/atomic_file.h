#ifndef KINCAL_DATA_ATOMIC_FILE_H_
#define KINCAL_DATA_ATOMIC_FILE_H_

#include <string>

namespace kincal {

// Writes `contents` to `path` through a temporary file in the same folder and
// a rename, so readers never see a partial file and a failed run leaves the
// old file (or none). Throws InputError when the folder is not writable.
void WriteFileAtomic(const std::string& path, const std::string& contents);

// Reads a whole file; throws InputError("<path>: cannot open ...") on failure.
std::string ReadFile(const std::string& path);

}  // namespace kincal

#endif  // KINCAL_DATA_ATOMIC_FILE_H_
