#ifndef KINCAL_VISION_TARGET_SHEET_H_
#define KINCAL_VISION_TARGET_SHEET_H_

// Print-ready calibration sheets (`kincal print`, docs/PRINT.md): what to
// draw, in millimetres on the paper, for a camcal target spec
// (vision/calib_target.h) or a tool's target.yaml (vision/target.h), and the
// writers of that drawing as PDF (cairo) and SVG (written directly, mm
// units).
//
// Every length on the sheet comes from the spec camcal and track read:
//   chessboard:COLSxROWS:SQUARE  (COLS+1) x (ROWS+1) squares of SQUARE mm,
//                                the top-left square black;
//   aprilgrid:COLSxROWS:TAG:R    tag36h11 tags, tag id's black square at
//                                CalibTargetSpec::Points()[4 id ..] (Kalibr's
//                                frame: ids from the bottom-left tag, y up),
//                                printed upright (TagImage's cells);
//   target.yaml                  each tag at its `size` (black-square edge),
//                                upright, labelled with id and size, spaced
//                                apart (the tags of a tool sit on different
//                                faces: cut them out and glue them on).
// Page frame: origin at the paper's top-left corner, x right, y down, mm.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "vision/calib_target.h"
#include "vision/target.h"

namespace kincal {

// Paper sizes (portrait width x height, mm): A4 210 x 297, A3 297 x 420,
// letter 215.9 x 279.4.
struct Paper {
  std::string name;
  double width_mm = 0;
  double height_mm = 0;
};
// InputError naming the papers known for any other name.
Paper PaperByName(const std::string& name);
// "A4, A3, letter", smallest first.
const std::vector<Paper>& KnownPapers();

struct SheetRect {  // filled black
  double x = 0, y = 0, width = 0, height = 0;
};
struct SheetLine {  // black stroke
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0, width = 0;
};
struct SheetText {                // black, left-aligned at (x, baseline y)
  double x = 0, y = 0, size = 0;  // size = font size, mm
  std::string text;
};

// Page layout (mm).
struct SheetOptions {
  std::string paper = "A4";
  double margin_mm = 10;  // white border of the page (printers' unprintable
                          // edge, and the chessboard's white quiet zone)
  double font_mm = 2.8;   // text height
  std::string command;    // the command line printed on the sheet
};

struct TargetSheet {
  Paper paper;  // as oriented: width x height of this page
  bool landscape = false;
  std::string target;   // the --target string or target.yaml path
  std::string command;  // the command line (also in the file's metadata)
  std::vector<SheetRect> black;  // cells and squares, black runs merged
  std::vector<SheetLine> lines;  // the scale bar
  std::vector<SheetText> texts;
  double board_width_mm = 0, board_height_mm = 0;  // the printed pattern
  // Where a target point (x, y) in target units lands on the page:
  // page = page_from_target_origin + (x, y_sign * y). Calib targets only
  // (AprilGrid: y up, y_sign = -1; chessboard: y_sign = +1).
  Eigen::Vector2d target_origin_on_page = Eigen::Vector2d::Zero();
  double target_y_sign = 1;
};

// Lays out a camcal target centred above the scale bar and the text, in
// portrait if it fits, else landscape. InputError when it fits neither way,
// naming the largest square/tag size that fits on this paper and the
// smallest known paper that holds the board as given.
TargetSheet LayoutCalibTargetSheet(const CalibTargetSpec& spec,
                                   const SheetOptions& options);

// Lays out every tag of a tool target, in id order, in rows, each with
// "id N, S mm" under it. InputError when they do not fit on one page.
TargetSheet LayoutToolTargetSheet(const Target& target,
                                  const std::string& target_path,
                                  const SheetOptions& options);

// The sheet as PDF (cairo; page = paper size in points, command line in the
// PDF's Subject metadata) and as SVG (width/height in mm, viewBox in mm,
// command line in an XML comment).
std::string SheetToPdf(const TargetSheet& sheet);
std::string SheetToSvg(const TargetSheet& sheet);

// Writes SheetToPdf or SheetToSvg by the extension of `path` (.pdf, .svg)
// through a temporary file and a rename; InputError for another extension.
void WriteTargetSheet(const TargetSheet& sheet, const std::string& path);

}  // namespace kincal

#endif  // KINCAL_VISION_TARGET_SHEET_H_
