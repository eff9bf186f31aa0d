// kincal print: a print-ready calibration sheet at physical size
// (vision/target_sheet.h, docs/PRINT.md).

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>

#include "app/app_util.h"
#include "app/command.h"
#include "app/front_end.h"
#include "data/error.h"
#include "data/provenance.h"
#include "vision/calib_target.h"
#include "vision/target.h"
#include "vision/target_sheet.h"

namespace kincal::app {
namespace {

struct PrintArgs {
  std::string target, out, paper = "A4";
  bool json = false;
};

double RoundMicrometre(double mm) { return std::round(mm * 1000) / 1000; }

int RunPrint(const PrintArgs& args) {
  SheetOptions options;
  options.paper = args.paper;
  options.command = CommandLine();
  // A spec has a colon (chessboard:..., aprilgrid:..., or a misspelt kind,
  // which ParseCalibTargetSpec names); anything else is a target.yaml path.
  const bool spec = args.target.find(':') != std::string::npos;
  if (!spec && !std::ifstream(args.target)) {
    throw InputError("--target '" + args.target +
                     "': no such file; expected "
                     "chessboard:COLSxROWS:SQUARE, "
                     "aprilgrid:COLSxROWS:TAG_SIZE:SPACING_RATIO (e.g. "
                     "chessboard:9x6:20) or a target.yaml");
  }
  const TargetSheet sheet =
      spec ? LayoutCalibTargetSheet(ParseCalibTargetSpec(args.target), options)
           : LayoutToolTargetSheet(ReadTargetYaml(args.target), args.target,
                                   options);
  WriteTargetSheet(sheet, args.out);
  if (args.json) {
    PrintJson({{"out", args.out},
               {"width_mm", sheet.paper.width_mm},
               {"height_mm", sheet.paper.height_mm},
               {"target", sheet.target},
               {"paper", sheet.paper.name},
               {"orientation", sheet.landscape ? "landscape" : "portrait"},
               {"pattern_mm",
                {RoundMicrometre(sheet.board_width_mm),
                 RoundMicrometre(sheet.board_height_mm)}}});
    return 0;
  }
  std::printf(
      "kincal print: %s -> %s (%s %s, %g x %g mm; pattern %g x %g mm)\n"
      "  print at 100 %% / actual size, no fit-to-page; the scale bar must "
      "measure 100 mm\n",
      sheet.target.c_str(), args.out.c_str(), sheet.paper.name.c_str(),
      sheet.landscape ? "landscape" : "portrait", sheet.paper.width_mm,
      sheet.paper.height_mm, sheet.board_width_mm, sheet.board_height_mm);
  return 0;
}

}  // namespace

void AddPrintCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<PrintArgs>();
  CLI::App* sub = app.add_subcommand("print", kPrintDescription);
  sub->add_option("--target", args->target,
                  "chessboard:COLSxROWS:SQUARE, "
                  "aprilgrid:COLSxROWS:TAG_SIZE:SPACING_RATIO (as camcal "
                  "reads it) or a tool's target.yaml (as track reads it); "
                  "sizes in mm")
      ->required();
  sub->add_option("--out", args->out, "SHEET.pdf or SHEET.svg to write")
      ->required();
  sub->add_option("--paper", args->paper, "A4, A3 or letter");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example: the chessboard for camcal, on A4:\n  kincal print --target "
      "chessboard:9x6:20 --out board.pdf\n  then print at 100 % (actual "
      "size) and measure the 100 mm scale bar"));
  sub->callback([run, args] { *run = [args] { return RunPrint(*args); }; });
}

}  // namespace kincal::app
