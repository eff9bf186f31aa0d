#include "report/iso9283_section.h"

namespace kincal {

void AddIso9283Section(const ReportAnalysis& an, const ReportOptions& options,
                       HtmlReport* page) {
  if (!an.has_iso9283) return;
  const Iso9283Result& r = an.iso9283;
  page->Section("iso9283", "ISO 9283 pose accuracy and repeatability");
  page->Paragraph(
      "Per commanded pose (fixed_point label) of " + options.iso9283 +
      ", robot model " + an.iso9283_robot +
      ": the barycentre of the attained positions, its distance from the "
      "commanded position (AP, components AP_x, AP_y, AP_z in the base "
      "frame) and the repeatability RP = l̄ + 3 S_l of the distances l "
      "from the barycentre. Positions only: the observations carry no "
      "orientations.");
  std::vector<std::string> header = {"pose",   "n",        "AP (mm)",
                                     "AP_x",   "AP_y",     "AP_z",
                                     "l̄ (mm)", "S_l (mm)", "RP (mm)"};
  if (r.tolerance_given) header.push_back("pass");
  std::vector<std::vector<std::string>> rows;
  for (const Iso9283Pose& p : r.poses) {
    std::vector<std::string> row = {p.label,
                                    std::to_string(p.n),
                                    Fmt(p.ap_mm),
                                    Fmt(p.ap_xyz_mm.x()),
                                    Fmt(p.ap_xyz_mm.y()),
                                    Fmt(p.ap_xyz_mm.z()),
                                    Fmt(p.l_mean_mm),
                                    Fmt(p.s_l_mm),
                                    Fmt(p.rp_mm)};
    if (r.tolerance_given) row.push_back(p.pass ? "yes" : "NO");
    rows.push_back(row);
  }
  page->Table(header, rows);
  std::string summary = "Largest AP " + Fmt(r.ap_max_mm) + " mm, largest RP " +
                        Fmt(r.rp_max_mm) + " mm.";
  if (r.tolerance_given) {
    summary += std::string(r.pass ? " PASS" : " FAIL") + ": every pose's AP " +
               "and RP within " + Fmt(options.tolerance_mm) + " mm" +
               (r.pass ? "." : " is not met.");
  }
  page->Paragraph(summary);
  page->Paragraph(
      "Measuring frame registered on the tested poses themselves (" +
      std::to_string(r.registration_rows) + " rows, residual RMS " +
      Fmt(r.registration_rms_mm) +
      " mm): the rigid fit takes up the part of the AP vectors that a rigid "
      "motion of the poses explains, so these AP are a lower bound of the "
      "AP against an independently registered frame (kincal iso9283 "
      "--frame-from; docs/ISO9283.md). RP does not depend on the frame.");
}

}  // namespace kincal
