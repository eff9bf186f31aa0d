#include "report/report.h"

#include <sys/stat.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "data/atomic_file.h"
#include "data/provenance.h"
#include "report/analysis.h"
#include "report/camera_sections.h"
#include "report/html.h"
#include "report/iso9283_section.h"
#include "report/robot_sections.h"
#include "report/verdict.h"

namespace kincal {
namespace {

bool Exists(const std::string& path) {
  struct stat st;
  return !path.empty() && ::stat(path.c_str(), &st) == 0;
}

// "# ..." provenance lines of a text file (first 6 comment lines) or the
// "command" of a JSON object.
std::vector<std::string> Provenance(const std::string& path) {
  std::vector<std::string> out;
  std::ifstream in(path);
  std::string line;
  int comments = 0;
  bool first = true;
  while (std::getline(in, line) && comments < 6) {
    if (first && !line.empty() && line[0] == '{') {
      try {
        const auto j = nlohmann::json::parse(ReadFile(path));
        if (j.contains("command"))
          out.push_back(j["command"].get<std::string>());
        if (j.contains("kincal_version")) {
          out.push_back(j["kincal_version"].get<std::string>());
        }
      } catch (const std::exception&) {
      }
      return out;
    }
    first = false;
    size_t at = line.find_first_not_of(" \t");
    if (at == std::string::npos) continue;
    if (line.compare(at, 4, "<!--") == 0 || line[at] == '#') {
      out.push_back(line.substr(at));
      ++comments;
    } else if (line[at] != '<') {
      break;
    }
  }
  return out;
}

void AddVerdictSection(const std::vector<std::string>& verdict,
                       const ToleranceCheck& tolerance, HtmlReport* page) {
  page->Section("verdict", "Verdict");
  std::string html = "<div class='verdict'>";
  for (const auto& v : verdict) {
    const bool tol = tolerance.given && v == tolerance.words;
    const char* tol_class = !tolerance.decided ? "undecided"
                            : tolerance.pass   ? "pass"
                                               : "fail";
    html += tol ? std::string("<p class='") + tol_class + "'>" + XmlEscape(v) +
                      "</p>"
                : "<p>" + XmlEscape(v) + "</p>";
  }
  page->Raw(html + "</div>");
}

void AddProvenanceSection(const ReportInputs& in, const ReportOptions& opt,
                          const std::vector<std::string>& notes,
                          HtmlReport* page) {
  page->Section("provenance", "Inputs and the commands that made them");
  std::vector<std::vector<std::string>> rows;
  auto add = [&](const std::string& what, const std::string& path) {
    if (path.empty() || !Exists(path)) return;
    std::string cmd;
    for (const auto& l : Provenance(path)) {
      cmd += (cmd.empty() ? "" : " | ") + l;
    }
    rows.push_back(
        {what, path, cmd.empty() ? "(no provenance recorded)" : cmd});
  };
  add("robot", opt.robot);
  add("observations", opt.obs);
  add("ISO 9283 cycles", opt.iso9283);
  add("calibrated robot", opt.calibrated);
  add("diagnosis", opt.diagnosis);
  add("bundle result", opt.bundle);
  add("rig", opt.rig);
  add("camcal JSON", in.camcal_path);
  if (!opt.session.empty()) {
    add("session", opt.session + "/session.yaml");
    add("session frames", opt.session + "/frames.csv");
    add("tracked points", in.points_path);
  }
  page->Table({"input", "file", "made by"}, rows);
  page->Raw("<p>This report: <code>" + XmlEscape(CommandLine()) + "</code> (" +
            XmlEscape(ToolVersion()) + ").</p>");
  for (const auto& n : notes) {
    page->Raw("<p class='note'>" + XmlEscape(n) + "</p>");
  }
}

}  // namespace

ReportResult BuildReport(
    const ReportOptions& opt,
    const std::function<void(const std::string&)>& progress) {
  // 1. Read every input: bad input fails before any computation.
  const ReportInputs in = ReadReportInputs(opt);
  // 2. Compute what the page shows.
  const ReportAnalysis an = AnalyseReport(in, opt, progress);
  // 3. The verdict in words, then one section after another.
  const ToleranceCheck tolerance = CheckTolerance(in, an, opt);
  const std::string name = in.has_robot ? in.robot.name
                           : in.has_cal ? in.cal.name
                                        : std::string("cameras and tracking");
  HtmlReport page("kincal report: " + name);
  AddVerdictSection(WriteVerdict(in, an, opt), tolerance, &page);
  AddDiagnosisSection(in, opt, &page);
  if (progress && an.has_geo) progress("drawing the figures");
  AddResidualsSection(in, an, opt, &page);
  AddStructureSection(in, an, opt, &page);
  AddWorkspaceSection(an, opt, &page);
  AddSensitivitySection(an, &page);
  AddClearanceSection(an, &page);
  AddIdentifiabilitySection(in, an, &page);
  AddParametersSection(in, an, opt, &page);
  AddIso9283Section(an, opt, &page);
  if (in.has_rig) AddCameraSection(in.rig, in.camcal, in.camcal_path, &page);
  if (!in.points_path.empty()) {
    AddTrackingSection(in.points_path, Exists(in.points_path), &page);
  }
  AddProvenanceSection(in, opt, an.notes, &page);

  ReportResult result;
  result.html = page.Page("Written by " + ToolVersion() +
                          ". One self-contained file: no network needed; "
                          "figures are vector graphics (zoom, print).");
  result.sections = page.sections();
  result.figures = page.figures();
  result.notes = an.notes;
  result.tolerance_given = tolerance.given;
  result.tolerance_available = tolerance.available;
  result.tolerance_decided = tolerance.decided;
  result.pass = tolerance.pass;
  result.tolerance_mm = tolerance.tolerance_mm;
  result.heldout_rms_mm = tolerance.heldout.rms_mm;
  result.heldout_lo_mm = tolerance.lo_mm;
  result.heldout_hi_mm = tolerance.hi_mm;
  result.heldout_n = tolerance.heldout.n;
  result.has_iso9283 = an.has_iso9283;
  result.iso9283_ap_max_mm = an.iso9283.ap_max_mm;
  result.iso9283_rp_max_mm = an.iso9283.rp_max_mm;
  result.iso9283_pass = an.iso9283.pass;
  return result;
}

}  // namespace kincal
