#include "data/csv.h"

#include <cmath>
#include <cstdlib>

#include "data/error.h"

namespace kincal {

std::vector<CsvLine> TokenizeCsv(const std::string& text,
                                 const std::string& file, char separator) {
  std::vector<CsvLine> out;
  size_t pos = 0;
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) pos = 3;  // UTF-8 BOM
  int line_no = 0;
  while (pos < text.size()) {
    ++line_no;
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;

    CsvLine cl;
    cl.line = line_no;
    cl.end_column = static_cast<int>(line.size()) + 1;
    size_t i = 0;
    while (true) {
      CsvField f;
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      f.column = static_cast<int>(i) + 1;
      if (i < line.size() && line[i] == '"') {
        ++i;
        bool closed = false;
        while (i < line.size()) {
          if (line[i] == '"') {
            if (i + 1 < line.size() && line[i + 1] == '"') {
              f.text += '"';
              i += 2;
              continue;
            }
            closed = true;
            ++i;
            break;
          }
          f.text += line[i++];
        }
        if (!closed) {
          throw InputError(file, line_no, f.column,
                           "unterminated quoted field");
        }
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        if (i < line.size() && line[i] != separator) {
          throw InputError(
              file, line_no, static_cast<int>(i) + 1,
              std::string("expected '") + separator + "' after quoted field");
        }
      } else {
        const size_t sep = line.find(separator, i);
        const size_t stop = sep == std::string::npos ? line.size() : sep;
        f.text = line.substr(i, stop - i);
        while (!f.text.empty() &&
               (f.text.back() == ' ' || f.text.back() == '\t')) {
          f.text.pop_back();
        }
        i = stop;
      }
      cl.fields.push_back(f);
      if (i >= line.size()) break;
      ++i;  // skip the separator; a trailing one yields an empty last field
      if (i == line.size()) {
        CsvField empty;
        empty.column = static_cast<int>(i) + 1;
        cl.fields.push_back(empty);
        break;
      }
    }
    out.push_back(cl);
  }
  return out;
}

bool ParseFiniteDouble(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

std::string CsvQuote(const std::string& text) {
  if (text.find_first_of(",\" \t#") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace kincal
