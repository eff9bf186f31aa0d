#ifndef KINCAL_REPORT_ROBOT_SECTIONS_H_
#define KINCAL_REPORT_ROBOT_SECTIONS_H_

// The report's sections about the robot (report/report.h lists them all),
// one function each, written from what report/analysis.h read and computed.
// Each adds its section to `page` only when its inputs are there.

#include "report/analysis.h"
#include "report/html.h"

namespace kincal {

// Plot sizes shared by every figure (px at 1:1; two small plots fit side by
// side in the page's 1036 px column).
constexpr int kSmallPlotWidth = 500;
constexpr int kWidePlotWidth = 1000;

void AddDiagnosisSection(const ReportInputs& in, const ReportOptions& options,
                         HtmlReport* page);
void AddResidualsSection(const ReportInputs& in, const ReportAnalysis& an,
                         const ReportOptions& options, HtmlReport* page);
void AddStructureSection(const ReportInputs& in, const ReportAnalysis& an,
                         const ReportOptions& options, HtmlReport* page);
void AddWorkspaceSection(const ReportAnalysis& an, const ReportOptions& options,
                         HtmlReport* page);
void AddSensitivitySection(const ReportAnalysis& an, HtmlReport* page);
void AddClearanceSection(const ReportAnalysis& an, HtmlReport* page);
// From the calibration run here, or from a bundle result (--bundle).
void AddIdentifiabilitySection(const ReportInputs& in, const ReportAnalysis& an,
                               HtmlReport* page);
void AddParametersSection(const ReportInputs& in, const ReportAnalysis& an,
                          const ReportOptions& options, HtmlReport* page);

}  // namespace kincal

#endif  // KINCAL_REPORT_ROBOT_SECTIONS_H_
