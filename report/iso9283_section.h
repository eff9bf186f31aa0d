#ifndef KINCAL_REPORT_ISO9283_SECTION_H_
#define KINCAL_REPORT_ISO9283_SECTION_H_

// The report's ISO 9283 section (report --iso9283 CYCLES.csv): pose accuracy
// AP and pose repeatability RP per commanded pose (diagnose/iso9283.h), with
// pass/fail against --tolerance, and how the measuring frame was registered.

#include "report/analysis.h"
#include "report/html.h"

namespace kincal {

// Nothing unless the analysis has ISO 9283 figures (an.has_iso9283).
void AddIso9283Section(const ReportAnalysis& an, const ReportOptions& options,
                       HtmlReport* page);

}  // namespace kincal

#endif  // KINCAL_REPORT_ISO9283_SECTION_H_
