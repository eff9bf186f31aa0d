#include "vision/target_sheet.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <opencv2/core.hpp>
#include <optional>
#include <sstream>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "vision/apriltag_detector.h"

namespace kincal {
namespace {

constexpr double kPointsPerMm = 72.0 / 25.4;
constexpr double kScaleBarMm = 100;
constexpr double kTickMm = 10;
constexpr double kLineWidthMm = 0.25;
constexpr double kBarHeightMm = 5;         // long ticks; short ticks are 3/5
constexpr double kFooterGapMm = 5;         // between the pattern and the bar
constexpr double kToolTagGapMm = 10;       // between the tags of a tool
constexpr double kCharWidthPerFont = 0.6;  // wide estimate for wrapping

// A length for text: no trailing zeros ("25", "23.3", "215.9").
std::string Mm(double v) {
  std::ostringstream os;
  os.precision(6);
  os << (std::abs(v) < 5e-7 ? 0.0 : v);
  return os.str();
}

// Fixed 4 decimals without trailing zeros, for SVG coordinates.
std::string Coord(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.4f", v);
  std::string s = buf;
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

// Splits `text` into lines of at most `width` characters, at spaces where
// possible (a longer word is cut).
std::vector<std::string> Wrap(const std::string& text, size_t width) {
  std::vector<std::string> lines;
  std::string rest = text;
  while (rest.size() > width) {
    size_t cut = rest.rfind(' ', width);
    if (cut == std::string::npos || cut == 0) cut = width;
    lines.push_back(rest.substr(0, cut));
    rest = rest.substr(cut);
    if (!rest.empty() && rest.front() == ' ') rest.erase(0, 1);
  }
  lines.push_back(rest);
  return lines;
}

Paper Oriented(const Paper& paper, bool landscape) {
  Paper p = paper;
  if (landscape) std::swap(p.width_mm, p.height_mm);
  return p;
}

// The text block under the scale bar: `lines` wrapped to the page width.
std::vector<std::string> WrapLines(const std::vector<std::string>& lines,
                                   const Paper& page,
                                   const SheetOptions& options) {
  const size_t width = static_cast<size_t>(
      std::max(20.0, (page.width_mm - 2 * options.margin_mm) /
                         (kCharWidthPerFont * options.font_mm)));
  std::vector<std::string> out;
  for (const std::string& line : lines) {
    for (const std::string& part : Wrap(line, width)) out.push_back(part);
  }
  return out;
}

double LineSpacing(const SheetOptions& options) {
  return 1.5 * options.font_mm;
}

// Height of the scale bar with its labels and of `n_lines` text lines.
double FooterHeight(size_t n_lines, const SheetOptions& options) {
  return kBarHeightMm + 1 + options.font_mm + 2 +
         static_cast<double>(n_lines) * LineSpacing(options);
}

// The space left for the pattern above the footer, mm.
Eigen::Vector2d PatternArea(const Paper& page, size_t n_lines,
                            const SheetOptions& options) {
  return Eigen::Vector2d(page.width_mm - 2 * options.margin_mm,
                         page.height_mm - 2 * options.margin_mm - kFooterGapMm -
                             FooterHeight(n_lines, options));
}

// Scale bar and text lines at the bottom of the page.
void AddFooter(const std::vector<std::string>& lines,
               const SheetOptions& options, TargetSheet* sheet) {
  const double x0 = options.margin_mm;
  const double top = sheet->paper.height_mm - options.margin_mm -
                     FooterHeight(lines.size(), options);
  const double base = top + kBarHeightMm;
  sheet->lines.push_back({x0, base, x0 + kScaleBarMm, base, kLineWidthMm});
  for (int k = 0; k * kTickMm <= kScaleBarMm + 1e-9; ++k) {
    const double x = x0 + k * kTickMm;
    const bool long_tick = k % 5 == 0;
    const double y_top = long_tick ? top : top + 2 * kBarHeightMm / 5;
    sheet->lines.push_back({x, y_top, x, base, kLineWidthMm});
    if (long_tick) {
      const std::string label =
          k * kTickMm == kScaleBarMm ? "100 mm" : Mm(k * kTickMm);
      sheet->texts.push_back({x - (k == 0 ? 0 : 0.3 * options.font_mm),
                              base + 1 + options.font_mm, options.font_mm,
                              label});
    }
  }
  sheet->texts.push_back({x0 + kScaleBarMm + 8, base, options.font_mm,
                          "first to last tick: 100 mm"});
  double y = base + 1 + options.font_mm + 2 + options.font_mm;
  for (const std::string& line : lines) {
    sheet->texts.push_back({x0, y, options.font_mm, line});
    y += LineSpacing(options);
  }
}

const char kPrintAdvice[] =
    "Print at 100 % / actual size, no fit-to-page; check the 100 mm bar with "
    "a ruler before use.";

// Black cells of one tag, its black square's top-left corner at `corner`
// (page mm), edge `size_mm`, turned by rotation_deg counter-clockwise; runs
// of black cells in a row merged.
void AddTag(const std::string& family, int id, double size_mm,
            const Eigen::Vector2d& corner, std::vector<SheetRect>* black,
            int rotation_deg = 0) {
  cv::Mat image = TagImage(family, id);
  if (rotation_deg == 90)
    cv::rotate(image, image, cv::ROTATE_90_COUNTERCLOCKWISE);
  if (rotation_deg == 180) cv::rotate(image, image, cv::ROTATE_180);
  if (rotation_deg == 270) cv::rotate(image, image, cv::ROTATE_90_CLOCKWISE);
  const int square_cells = TagBlackSquareCells(family);
  const int start = (image.cols - square_cells) / 2;
  const double cell = size_mm / square_cells;
  const Eigen::Vector2d origin = corner - Eigen::Vector2d(start, start) * cell;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols;) {
      if (image.at<uint8_t>(r, c) != 0) {
        ++c;
        continue;
      }
      int end = c;
      while (end < image.cols && image.at<uint8_t>(r, end) == 0) ++end;
      black->push_back({origin.x() + c * cell, origin.y() + r * cell,
                        (end - c) * cell, cell});
      c = end;
    }
  }
}

// Printed edge of a tag including the cells around its black square.
double TagPrintedEdge(const std::string& family, double size_mm) {
  const cv::Mat image = TagImage(family, 0);
  return size_mm * image.cols / TagBlackSquareCells(family);
}

// Board size per unit of the spec's size (square or tag edge).
Eigen::Vector2d BoardPerUnit(const CalibTargetSpec& spec) {
  if (spec.kind == CalibTargetSpec::Kind::kChessboard) {
    return Eigen::Vector2d(spec.cols + 1, spec.rows + 1);
  }
  return Eigen::Vector2d(spec.cols + (spec.cols - 1) * spec.spacing_ratio,
                         spec.rows + (spec.rows - 1) * spec.spacing_ratio);
}

std::string DescribeCalibTarget(const CalibTargetSpec& spec) {
  const Eigen::Vector2d board = BoardPerUnit(spec) * spec.size;
  std::ostringstream os;
  os << "target: " << spec.text << "  (";
  if (spec.kind == CalibTargetSpec::Kind::kChessboard) {
    os << spec.cols << " x " << spec.rows << " inner corners, " << spec.cols + 1
       << " x " << spec.rows + 1 << " squares of " << Mm(spec.size) << " mm";
  } else {
    os << spec.cols << " x " << spec.rows << " tag36h11 tags, ids "
       << spec.first_id << "-" << spec.first_id + spec.cols * spec.rows - 1
       << (spec.column_major ? " column by column" : " row by row")
       << (spec.origin_top ? " from the top-left" : " from the bottom-left")
       << (spec.rotation_deg
               ? ", turned " + std::to_string(spec.rotation_deg) + " deg"
               : std::string())
       << "; black square " << Mm(spec.size) << " mm, gap "
       << Mm(spec.spacing_ratio * spec.size) << " mm";
  }
  os << "; pattern " << Mm(board.x()) << " x " << Mm(board.y()) << " mm)";
  return os.str();
}

struct Fit {
  bool landscape = false;
  std::vector<std::string> lines;
  Eigen::Vector2d area;
};

// Portrait if the board fits, else landscape; nullopt when neither.
std::optional<Fit> FitBoard(const Paper& paper, const Eigen::Vector2d& board,
                            const std::vector<std::string>& text,
                            const SheetOptions& options) {
  for (bool landscape : {false, true}) {
    Fit fit;
    fit.landscape = landscape;
    const Paper page = Oriented(paper, landscape);
    fit.lines = WrapLines(text, page, options);
    fit.area = PatternArea(page, fit.lines.size(), options);
    if (board.x() <= fit.area.x() + 1e-9 && board.y() <= fit.area.y() + 1e-9) {
      return fit;
    }
  }
  return std::nullopt;
}

// The message when the board fits on neither orientation of `paper`.
[[noreturn]] void ThrowDoesNotFit(const CalibTargetSpec& spec,
                                  const Paper& paper,
                                  const std::vector<std::string>& text,
                                  const SheetOptions& options) {
  const Eigen::Vector2d per_unit = BoardPerUnit(spec);
  double largest = 0;
  for (bool landscape : {false, true}) {
    const Paper page = Oriented(paper, landscape);
    const Eigen::Vector2d area =
        PatternArea(page, WrapLines(text, page, options).size(), options);
    largest = std::max(
        largest, std::min(area.x() / per_unit.x(), area.y() / per_unit.y()));
  }
  largest = std::floor(largest * 10) / 10;
  const Eigen::Vector2d board = per_unit * spec.size;
  std::string larger;
  for (const Paper& other : KnownPapers()) {
    SheetOptions o = options;
    o.paper = other.name;
    if (other.width_mm * other.height_mm > paper.width_mm * paper.height_mm &&
        FitBoard(other, board, text, o)) {
      larger = other.name;
      break;
    }
  }
  std::ostringstream os;
  os << "--target '" << spec.text << "': the pattern is " << Mm(board.x())
     << " x " << Mm(board.y()) << " mm and does not fit on " << paper.name
     << " (" << Mm(paper.width_mm) << " x " << Mm(paper.height_mm)
     << " mm, with " << Mm(options.margin_mm)
     << " mm margins, the scale bar and the text): the largest "
     << (spec.kind == CalibTargetSpec::Kind::kChessboard ? "square" : "tag")
     << " size that fits is " << Mm(largest) << " mm";
  if (!larger.empty()) {
    os << ", or use --paper " << larger;
  } else {
    os << " (no known paper holds it as given: "
       << "A4, A3, letter)";
  }
  throw InputError(os.str());
}

// Black squares of a chessboard whose top-left corner is at `corner`.
void AddChessboard(const CalibTargetSpec& spec, const Eigen::Vector2d& corner,
                   TargetSheet* sheet) {
  for (int row = 0; row <= spec.rows; ++row) {
    for (int col = 0; col <= spec.cols; ++col) {
      if ((row + col) % 2 != 0) continue;
      sheet->black.push_back({corner.x() + col * spec.size,
                              corner.y() + row * spec.size, spec.size,
                              spec.size});
    }
  }
  sheet->target_origin_on_page = corner + Eigen::Vector2d(spec.size, spec.size);
  sheet->target_y_sign = 1;
}

// Tags of an AprilGrid whose top-left corner is at `corner`, each at its
// black square's top-left corner from CalibTargetSpec::Points() (Kalibr's
// frame, y up: page = origin + (x, -y)).
void AddAprilGrid(const CalibTargetSpec& spec, const Eigen::Vector2d& corner,
                  double board_height, TargetSheet* sheet) {
  sheet->target_origin_on_page = corner + Eigen::Vector2d(0, board_height);
  sheet->target_y_sign = -1;
  const double pitch = spec.size * (1.0 + spec.spacing_ratio);
  for (int index = 0; index < spec.cols * spec.rows; ++index) {
    // The black square's top-left corner (target frame, y up).
    const Eigen::Vector2i cell = spec.TagCell(index);
    const Eigen::Vector2d top_left(cell.x() * pitch,
                                   cell.y() * pitch + spec.size);
    AddTag("tag36h11", spec.first_id + index, spec.size,
           sheet->target_origin_on_page +
               Eigen::Vector2d(top_left.x(), -top_left.y()),
           &sheet->black, spec.rotation_deg);
  }
}

}  // namespace

const std::vector<Paper>& KnownPapers() {
  static const std::vector<Paper> papers = {
      {"letter", 215.9, 279.4}, {"A4", 210, 297}, {"A3", 297, 420}};
  return papers;
}

Paper PaperByName(const std::string& name) {
  for (const Paper& p : KnownPapers()) {
    if (p.name == name) return p;
  }
  throw InputError("--paper '" + name + "': expected A4, A3 or letter");
}

TargetSheet LayoutCalibTargetSheet(const CalibTargetSpec& spec,
                                   const SheetOptions& options) {
  const Paper paper = PaperByName(options.paper);
  const std::vector<std::string> text = {
      DescribeCalibTarget(spec), kPrintAdvice, "made by: " + options.command};
  const Eigen::Vector2d board = BoardPerUnit(spec) * spec.size;
  const std::optional<Fit> fit = FitBoard(paper, board, text, options);
  if (!fit) ThrowDoesNotFit(spec, paper, text, options);
  TargetSheet sheet;
  sheet.paper = Oriented(paper, fit->landscape);
  sheet.landscape = fit->landscape;
  sheet.target = spec.text;
  sheet.command = options.command;
  sheet.board_width_mm = board.x();
  sheet.board_height_mm = board.y();
  const Eigen::Vector2d corner =
      Eigen::Vector2d(options.margin_mm, options.margin_mm) +
      (fit->area - board) / 2;
  if (spec.kind == CalibTargetSpec::Kind::kChessboard) {
    AddChessboard(spec, corner, &sheet);
  } else {
    AddAprilGrid(spec, corner, board.y(), &sheet);
  }
  AddFooter(fit->lines, options, &sheet);
  return sheet;
}

TargetSheet LayoutToolTargetSheet(const Target& target,
                                  const std::string& target_path,
                                  const SheetOptions& options) {
  std::vector<TargetTag> tags = target.tags;
  std::sort(tags.begin(), tags.end(),
            [](const TargetTag& a, const TargetTag& b) { return a.id < b.id; });
  std::ostringstream summary;
  summary << "target: " << target_path << "  (" << target.family << ":";
  for (const TargetTag& tag : tags) {
    summary << " id " << tag.id << " " << Mm(tag.size_mm) << " mm"
            << (&tag == &tags.back() ? "" : ",");
  }
  summary << "; size = edge of the black square)";
  const std::vector<std::string> text = {summary.str(), kPrintAdvice,
                                         "made by: " + options.command};
  TargetSheet sheet;
  sheet.paper = PaperByName(options.paper);
  sheet.target = target_path;
  sheet.command = options.command;
  const std::vector<std::string> lines = WrapLines(text, sheet.paper, options);
  const Eigen::Vector2d area = PatternArea(sheet.paper, lines.size(), options);
  const double label = 1.5 * options.font_mm;
  double x = 0, y = 0, row_height = 0;
  for (const TargetTag& tag : tags) {
    const double edge = TagPrintedEdge(target.family, tag.size_mm);
    const double slot_width = std::max(edge, 16 * options.font_mm);
    if (edge > area.x() || edge + label > area.y()) {
      const double largest = std::floor(std::min(area.x(), area.y() - label) /
                                        edge * tag.size_mm * 10) /
                             10;
      throw InputError(target_path + ": tag id " + std::to_string(tag.id) +
                       " (" + Mm(tag.size_mm) + " mm, " + Mm(edge) +
                       " mm with its white border) does not fit on " +
                       sheet.paper.name + ": the largest tag that fits is " +
                       Mm(largest) + " mm, or use a larger --paper (A3)");
    }
    if (x > 0 && x + slot_width > area.x()) {
      x = 0;
      y += row_height + kToolTagGapMm;
      row_height = 0;
    }
    if (y + edge + label > area.y()) {
      throw InputError(target_path + ": its " + std::to_string(tags.size()) +
                       " tags do not fit on one " + sheet.paper.name +
                       " page; use --paper A3");
    }
    const Eigen::Vector2d border(options.margin_mm + x, options.margin_mm + y);
    const double inset = (edge - tag.size_mm) / 2;
    AddTag(target.family, tag.id, tag.size_mm,
           border + Eigen::Vector2d(inset, inset), &sheet.black);
    sheet.texts.push_back(
        {border.x(), border.y() + edge + label, options.font_mm,
         "id " + std::to_string(tag.id) + ", " + Mm(tag.size_mm) + " mm"});
    sheet.board_width_mm = std::max(sheet.board_width_mm, x + edge);
    sheet.board_height_mm = std::max(sheet.board_height_mm, y + edge + label);
    x += slot_width + kToolTagGapMm;
    row_height = std::max(row_height, edge + label);
  }
  AddFooter(lines, options, &sheet);
  return sheet;
}

namespace {

cairo_status_t AppendToString(void* closure, const unsigned char* data,
                              unsigned int length) {
  static_cast<std::string*>(closure)->append(
      reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

void DrawSheet(const TargetSheet& sheet, cairo_t* cr) {
  cairo_scale(cr, kPointsPerMm, kPointsPerMm);  // user units: mm
  cairo_set_source_rgb(cr, 0, 0, 0);
  // One path for every black cell: abutting cells fill as one shape, with
  // no seams where a rasteriser antialiases each rectangle's edges.
  cairo_new_path(cr);
  for (const SheetRect& r : sheet.black) {
    cairo_rectangle(cr, r.x, r.y, r.width, r.height);
  }
  cairo_set_fill_rule(cr, CAIRO_FILL_RULE_WINDING);
  cairo_fill(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  for (const SheetLine& l : sheet.lines) {
    cairo_set_line_width(cr, l.width);
    cairo_move_to(cr, l.x0, l.y0);
    cairo_line_to(cr, l.x1, l.y1);
    cairo_stroke(cr);
  }
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         CAIRO_FONT_WEIGHT_NORMAL);
  for (const SheetText& t : sheet.texts) {
    cairo_set_font_size(cr, t.size);
    cairo_move_to(cr, t.x, t.y);
    cairo_show_text(cr, t.text.c_str());
  }
  cairo_show_page(cr);
}

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// XML comments may not contain "--": written "- -" there (the exact command
// is in <desc>).
std::string CommentSafe(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '-' && !out.empty() && out.back() == '-') out += ' ';
    out += c;
  }
  return out;
}

}  // namespace

std::string SheetToPdf(const TargetSheet& sheet) {
  std::string pdf;
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(
      AppendToString, &pdf, sheet.paper.width_mm * kPointsPerMm,
      sheet.paper.height_mm * kPointsPerMm);
  cairo_pdf_surface_set_metadata(
      surface, CAIRO_PDF_METADATA_TITLE,
      ("kincal calibration sheet: " + sheet.target).c_str());
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_SUBJECT,
                                 ("made by: " + sheet.command).c_str());
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR,
                                 ToolVersion().c_str());
  cairo_t* cr = cairo_create(surface);
  DrawSheet(sheet, cr);
  const cairo_status_t draw_status = cairo_status(cr);
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (draw_status != CAIRO_STATUS_SUCCESS || status != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(
        std::string("cairo could not write the PDF: ") +
        cairo_status_to_string(draw_status != CAIRO_STATUS_SUCCESS ? draw_status
                                                                   : status));
  }
  return pdf;
}

std::string SheetToSvg(const TargetSheet& sheet) {
  std::ostringstream os;
  const std::string w = Coord(sheet.paper.width_mm);
  const std::string h = Coord(sheet.paper.height_mm);
  os << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
     << "<!-- made by: " << CommentSafe(sheet.command) << " (" << ToolVersion()
     << ") -->\n"
     << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w
     << "mm\" height=\"" << h << "mm\" viewBox=\"0 0 " << w << " " << h
     << "\">\n"
     << "<title>kincal calibration sheet: " << XmlEscape(sheet.target)
     << "</title>\n"
     << "<desc>made by: " << XmlEscape(sheet.command) << "</desc>\n"
     << "<rect x=\"0\" y=\"0\" width=\"" << w << "\" height=\"" << h
     << "\" fill=\"white\"/>\n";
  os << "<path fill=\"black\" d=\"";
  for (const SheetRect& r : sheet.black) {
    os << "M" << Coord(r.x) << " " << Coord(r.y) << "h" << Coord(r.width) << "v"
       << Coord(r.height) << "h" << Coord(-r.width) << "z";
  }
  os << "\"/>\n";
  for (const SheetLine& l : sheet.lines) {
    os << "<line x1=\"" << Coord(l.x0) << "\" y1=\"" << Coord(l.y0)
       << "\" x2=\"" << Coord(l.x1) << "\" y2=\"" << Coord(l.y1)
       << "\" stroke=\"black\" stroke-width=\"" << Coord(l.width) << "\"/>\n";
  }
  for (const SheetText& t : sheet.texts) {
    os << "<text x=\"" << Coord(t.x) << "\" y=\"" << Coord(t.y)
       << "\" font-family=\"sans-serif\" font-size=\"" << Coord(t.size) << "\">"
       << XmlEscape(t.text) << "</text>\n";
  }
  os << "</svg>\n";
  return os.str();
}

void WriteTargetSheet(const TargetSheet& sheet, const std::string& path) {
  std::string ext = path.substr(std::min(path.size(), path.rfind('.')));
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".pdf") {
    WriteFileAtomic(path, SheetToPdf(sheet));
  } else if (ext == ".svg") {
    WriteFileAtomic(path, SheetToSvg(sheet));
  } else {
    throw InputError("--out '" + path +
                     "': expected a file ending in .pdf or .svg");
  }
}

}  // namespace kincal
