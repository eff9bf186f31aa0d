#ifndef KINCAL_REPORT_VERDICT_H_
#define KINCAL_REPORT_VERDICT_H_

// The report's verdict in words (report/report.h), with its wording rules:
//
//   - one held-out figure per model, with where it comes from: the
//     diagnosis' when one is given ("held out: 25 % of poses (60) by
//     diagnose model"), else a bundle result's, else the calibration run by
//     the report; fewer than kMinHeldOutPoses held-out poses are called a
//     rough figure;
//   - percentages only where the data support them: the share of the error
//     two joints explain needs kMinPosesForShares poses (a 5 x 5 grid's
//     chance level is 24 / n) and a share inside 0..100 %, else the verdict
//     says "too few poses";
//   - no finding reads "no significant effect";
//   - a bundle result (--bundle) is shown with its own figures (held-out tip
//     RMS, reprojection RMS, sigma0) and not re-run.

#include <string>
#include <vector>

#include "report/analysis.h"

namespace kincal {

constexpr int kMinHeldOutPoses = 30;
constexpr int kMinPosesForShares = 100;

// A model's error on poses held out of its fit.
struct HeldOutFigure {
  bool known = false;
  double rms_mm = 0.0;
  int n = 0;           // held-out poses (or tips)
  std::string source;  // e.g. "held out: 25 % of poses (60) by diagnose model"
};

// The geometric model's held-out figure and the final model's (the
// extended one when a diagnosis is given, else the geometric one).
HeldOutFigure GeometricHeldOut(const ReportInputs& in, const ReportAnalysis& an,
                               const ReportOptions& options);
HeldOutFigure FinalHeldOut(const ReportInputs& in, const ReportAnalysis& an,
                           const ReportOptions& options);

// Quantile p of the chi-square distribution with `dof` degrees of freedom
// (Wilson-Hilferty; within 0.5 % for dof >= 3).
double ChiSquareQuantile(double p, double dof);

// `report --tolerance`: the final held-out RMS against the tolerance with
// its 95 % interval from the chi-square distribution of the 3 n residual
// components of n held-out poses. Passes when the whole interval is at or
// below the tolerance; with fewer than kMinHeldOutPoses held-out poses it is
// not decided (no pass), and says so.
struct ToleranceCheck {
  // decided: available with at least kMinHeldOutPoses held-out poses;
  // pass means something only when decided.
  bool given = false, available = false, decided = false, pass = false;
  double tolerance_mm = 0.0;
  HeldOutFigure heldout;
  double lo_mm = 0.0, hi_mm = 0.0;  // 95 % interval of the held-out RMS
  std::string words;                // the line shown in the verdict
};
ToleranceCheck CheckTolerance(const ReportInputs& in, const ReportAnalysis& an,
                              const ReportOptions& options);

// The residual-structure sentence (also the structure figure's caption).
// Empty when no structure was computed.
std::string StructureSentence(const ReportInputs& in, const ReportAnalysis& an);

// The verdict's paragraphs, in order.
std::vector<std::string> WriteVerdict(const ReportInputs& in,
                                      const ReportAnalysis& an,
                                      const ReportOptions& options);

}  // namespace kincal

#endif  // KINCAL_REPORT_VERDICT_H_
