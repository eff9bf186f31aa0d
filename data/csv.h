#ifndef KINCAL_DATA_CSV_H_
#define KINCAL_DATA_CSV_H_

#include <string>
#include <vector>

namespace kincal {

// A minimal strict CSV tokenizer shared by the readers in data/: comma
// separated, optional double quotes ("" inside quotes is a quote), lines
// starting with '#' are comments, blank lines are skipped, a UTF-8 BOM and CRLF
// line ends are accepted. Each field keeps its 1-based column (character
// position) for messages; fields are trimmed of spaces.
struct CsvField {
  std::string text;
  int column = 1;
};
struct CsvLine {
  int line = 0;        // 1-based line number in the file
  int end_column = 1;  // column just past the last character
  std::vector<CsvField> fields;
};

// Throws InputError for an unterminated quote.
std::vector<CsvLine> TokenizeCsv(const std::string& text,
                                 const std::string& file_label,
                                 char separator = ',');

// Parses a finite double; false on anything else ("", "nan", "1e", "inf").
bool ParseFiniteDouble(const std::string& text, double* value);

// Quotes a field for writing when it contains a separator, quote or space.
std::string CsvQuote(const std::string& text);

}  // namespace kincal

#endif  // KINCAL_DATA_CSV_H_
