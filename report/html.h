#ifndef KINCAL_REPORT_HTML_H_
#define KINCAL_REPORT_HTML_H_

// A small builder for the one-file HTML report: sections with headings,
// paragraphs, tables and figures (inline SVG from data/svg_plot.h), inside a
// page with its own CSS and a few lines of script that check every figure
// drew. Nothing is loaded from outside the file.

#include <string>
#include <vector>

#include "data/svg_plot.h"

namespace kincal {

class HtmlReport {
 public:
  explicit HtmlReport(std::string title) : title_(std::move(title)) {}

  // Starts a section (id for the table of contents and the JSON `sections`).
  void Section(const std::string& id, const std::string& heading);
  void Paragraph(const std::string& text);              // escaped
  void Raw(const std::string& html);                    // trusted markup
  void Bullets(const std::vector<std::string>& items);  // escaped
  // A table; `header` and each row's cells are escaped.
  void Table(const std::vector<std::string>& header,
             const std::vector<std::vector<std::string>>& rows);
  // A figure with its caption; the plot is drawn as inline SVG.
  void Figure(const Plot& plot, const std::string& caption);
  // Several plots side by side (small multiples), one caption.
  void FigureRow(const std::vector<Plot>& plots, const std::string& caption);

  const std::vector<std::string>& sections() const { return ids_; }
  int figures() const { return figures_; }

  // The whole page. `footer` is escaped text under the last section.
  std::string Page(const std::string& footer) const;

 private:
  std::string title_;
  std::vector<std::string> ids_, headings_;
  std::string body_;
  int figures_ = 0;
};

// Formats a number with `digits` significant digits ("-" when not finite).
std::string Fmt(double v, int digits = 4);

}  // namespace kincal

#endif  // KINCAL_REPORT_HTML_H_
