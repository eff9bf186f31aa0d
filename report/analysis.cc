#include "report/analysis.h"

#include <sys/stat.h>

#include <fstream>
#include <regex>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/urdf.h"
#include "report/html.h"

namespace kincal {
namespace {

bool Exists(const std::string& path) {
  struct stat st;
  return !path.empty() && ::stat(path.c_str(), &st) == 0;
}

Robot WithoutExtensions(Robot r) {
  r.extensions.clear();
  return r;
}

// A JSON file another command printed; `what` names that command's output.
nlohmann::json ReadJsonObject(const std::string& path,
                              const std::string& what) {
  try {
    return nlohmann::json::parse(ReadFile(path));
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path, 0, 0, "expected " + what + ": " + e.what());
  }
}

void ReadRobotInputs(const ReportOptions& opt, ReportInputs* in) {
  if (!opt.robot.empty()) {
    in->robot = ReadRobot(opt.robot, opt.root, opt.tip);
    in->has_robot = true;
  }
  if (!opt.calibrated.empty()) {
    in->cal = ReadRobot(opt.calibrated, opt.root, opt.tip);
    in->has_cal = true;
    in->cal_header = ReadBundleHeader(opt.calibrated);
  }
  if (!opt.obs.empty()) {
    Require(in->has_robot || in->has_cal,
            "--obs needs --robot or --calibrated (the joint names)");
    in->obs = ReadObservationsCsv(opt.obs, in->JointRobot().JointNames());
    RequireOneSeries(in->obs, "report --obs");
    in->has_obs = true;
  }
  if (!opt.iso9283.empty()) {
    Require(in->has_robot || in->has_cal,
            "--iso9283 needs --robot or --calibrated (the model of the "
            "commanded positions)");
    in->iso9283_obs =
        ReadObservationsCsv(opt.iso9283, in->JointRobot().JointNames());
    in->has_iso9283 = true;
  }
  if (in->has_robot && in->has_cal) {
    Require(in->robot.JointNames() == in->cal.JointNames(),
            opt.calibrated + ": joints differ from " + opt.robot);
  }
}

void ReadResultInputs(const ReportOptions& opt, ReportInputs* in) {
  if (!opt.diagnosis.empty()) {
    in->diag = ReadJsonObject(
        opt.diagnosis, "the JSON printed by `kincal diagnose model --json`");
    if (!in->diag.is_object() || !in->diag.contains("verdict") ||
        !in->diag.contains("findings") || !in->diag["findings"].is_array()) {
      throw InputError(opt.diagnosis, 1, 1,
                       "expected an object with 'verdict' and 'findings' "
                       "(the output of `kincal diagnose model --json`)");
    }
    in->has_diag = true;
  }
  if (!opt.bundle.empty()) {
    in->bundle = ReadJsonObject(opt.bundle,
                                "the JSON printed by `kincal bundle --json`");
    if (!in->bundle.is_object() || !in->bundle.contains("reproj_rms_px") ||
        !in->bundle.contains("params")) {
      throw InputError(opt.bundle, 1, 1,
                       "expected an object with 'reproj_rms_px' and 'params' "
                       "(the output of `kincal bundle --json`)");
    }
    in->has_bundle = true;
  }
}

void ReadCameraInputs(const ReportOptions& opt, ReportInputs* in) {
  if (!opt.rig.empty()) {
    in->rig = ReadRigYaml(opt.rig);
    in->has_rig = true;
  }
  in->camcal_path = opt.camcal_json;
  if (in->camcal_path.empty() && in->has_rig) {  // camcal --json beside?
    const size_t dot = opt.rig.rfind('.');
    const std::string guess =
        (dot == std::string::npos ? opt.rig : opt.rig.substr(0, dot)) + ".json";
    if (Exists(guess)) in->camcal_path = guess;
  }
  if (!in->camcal_path.empty()) {
    in->camcal = ReadJsonObject(in->camcal_path, "camcal's JSON");
  }
  if (!opt.session.empty()) {
    Require(Exists(opt.session), opt.session + ": no such session folder");
    in->points_path = opt.session + "/points.csv";
    if (opt.session.size() > 4 &&
        opt.session.compare(opt.session.size() - 4, 4, ".csv") == 0) {
      in->points_path = opt.session;
    }
  }
}

StructureShare FindStructure(const ReportInputs& in, const ReportAnalysis& an) {
  StructureShare out;
  const int nj = in.JointCount();
  std::vector<std::vector<double>> qcol(nj);
  for (int j = 0; j < nj; ++j) {
    for (int row : an.res_geo.rows) qcol[j].push_back(in.obs.rows[row].q[j]);
  }
  for (int a = 0; a < nj; ++a) {
    for (int b = a + 1; b < nj; ++b) {
      const double s =
          VectorExplainedByGrid(qcol[a], qcol[b], an.res_geo.e_in_base, 5);
      if (s > out.pair) out.pair = s, out.a = a, out.b = b;
    }
  }
  out.poses = an.res_geo.stats.n;
  if (out.a < 0) return out;
  const std::vector<double> zero(qcol[out.a].size(), 0.0);
  out.a_alone =
      VectorExplainedByGrid(qcol[out.a], zero, an.res_geo.e_in_base, 5);
  out.b_alone =
      VectorExplainedByGrid(qcol[out.b], zero, an.res_geo.e_in_base, 5);
  if (an.has_ext && an.res_ext.rows == an.res_geo.rows) {
    out.with_extensions = VectorExplainedByGrid(qcol[out.a], qcol[out.b],
                                                an.res_ext.e_in_base, 5);
  }
  return out;
}

void ComputeResidualSets(const ReportInputs& in, ReportAnalysis* an) {
  if (in.has_robot) {
    an->res_nominal = ComputeResiduals(in.robot, in.obs, "nominal");
    an->has_nominal = true;
  }
  an->res_geo = ComputeResiduals(an->geometric, in.obs, "geometric model");
  an->has_geo = true;
  if (in.has_cal && !in.cal.extensions.empty()) {
    an->res_ext = ComputeResiduals(in.cal, in.obs, "with extensions");
    an->has_ext = true;
  }
}

void ComputeClearance(const ReportInputs& in, const ReportOptions& opt,
                      ReportAnalysis* an) {
  try {
    ClearanceOptions co;
    co.gamma = opt.gamma;
    // As `kincal diagnose clearance` does by default: calibrate the nominal
    // geometry on the same data first (without a nominal robot, the
    // geometric model as given).
    co.calibrate_geometry = in.has_robot;
    an->clear =
        DiagnoseClearance(in.has_robot ? in.robot : an->geometric, in.obs, co);
    an->has_clear = true;
  } catch (const InputError& e) {
    an->notes.push_back(std::string("clearance skipped: ") + e.what());
  }
}

void ComputeSensitivity(const ReportInputs& in, ReportAnalysis* an) {
  if (in.obs.CountWithFixedPoint() >= 2) {
    try {
      an->sensitivity =
          AnalyzeSensitivity(an->geometric, in.obs, SensitivityOptions());
      an->has_fixed_sensitivity = true;
    } catch (const InputError& e) {
      an->notes.push_back(std::string("sensitivity skipped: ") + e.what());
    }
    return;
  }
  // Measured points: the same curves with the RMS tip error, frame held.
  std::vector<std::string> skip;
  if (an->has_calres) skip = an->calres.identifiability.UnidentifiableNames();
  if (in.has_bundle && in.bundle.contains("unidentifiable")) {
    for (const auto& n : in.bundle["unidentifiable"]) {
      if (n.is_string()) skip.push_back(n.get<std::string>());
    }
  }
  an->measured_sensitivity =
      MeasuredSensitivity(an->geometric, in.obs, 5.0, 41, skip);
}

}  // namespace

BundleHeader ReadBundleHeader(const std::string& robot_path) {
  BundleHeader out;
  std::ifstream file(robot_path);
  std::string line;
  for (int k = 0; k < 8 && std::getline(file, line); ++k) {
    if (line.empty() || line[0] != '#') break;
    if (line.find("calibrated by kincal bundle") != std::string::npos) {
      out.found = true;
    }
    if (line.rfind("# reprojection RMS", 0) == 0) {
      // Numbers to 3 significant digits, as everywhere in the verdict.
      const std::string text = line.substr(2);
      const std::regex number("[0-9]+\\.[0-9]+(e-?[0-9]+)?");
      size_t last = 0;
      for (auto it = std::sregex_iterator(text.begin(), text.end(), number);
           it != std::sregex_iterator(); ++it) {
        out.reprojection +=
            text.substr(last, static_cast<size_t>(it->position()) - last) +
            Fmt(std::stod(it->str()), 3);
        last = static_cast<size_t>(it->position() + it->length());
      }
      out.reprojection += text.substr(last);
    }
  }
  return out;
}

ReportInputs ReadReportInputs(const ReportOptions& options) {
  ReportInputs in;
  ReadRobotInputs(options, &in);
  ReadResultInputs(options, &in);
  ReadCameraInputs(options, &in);
  return in;
}

double ChanceShare(int poses, int bins) {
  return static_cast<double>(bins * bins - 1) / std::max(1, poses);
}

ReportAnalysis AnalyseReport(
    const ReportInputs& in, const ReportOptions& opt,
    const std::function<void(const std::string&)>& progress_fn) {
  auto progress = [&](const std::string& what) {
    if (progress_fn) progress_fn(what);
  };
  ReportAnalysis an;
  if (in.has_iso9283) {
    progress("ISO 9283 pose accuracy and repeatability");
    Iso9283Options io;
    io.ap_tolerance_mm = opt.tolerance_mm;
    io.rp_tolerance_mm = opt.tolerance_mm;
    an.iso9283 = ComputeIso9283(in.JointRobot(), in.iso9283_obs, io);
    an.iso9283_robot = in.has_robot ? opt.robot : opt.calibrated;
    an.has_iso9283 = true;
  }
  const bool can_fit = in.has_obs && (in.has_robot || in.has_cal);
  if (!can_fit) return an;
  an.nominal = in.has_robot ? in.robot : WithoutExtensions(in.cal);
  // A bundle result brings its own fit (held-out tips, sigma): the report
  // shows it instead of a calibration of its own.
  if (!in.has_bundle) {
    progress("calibrating the geometry (held-out poses, identifiability)");
    try {
      CalibrateOptions co;
      co.seed = opt.seed;
      an.calres = Calibrate(an.nominal, in.obs, co);
      an.has_calres = true;
    } catch (const InputError& e) {
      an.notes.push_back(std::string("calibration skipped: ") + e.what());
    }
  }
  an.geometric = in.has_cal      ? WithoutExtensions(in.cal)
                 : an.has_calres ? an.calres.calibrated
                                 : an.nominal;
  progress("residuals of the nominal, geometric and extended models");
  ComputeResidualSets(in, &an);
  an.structure = FindStructure(in, an);
  if (in.obs.CountWithPoints() >= 3) {
    progress("the seed's Section 4 clearance sweeps");
    ComputeClearance(in, opt, &an);
  }
  progress("the seed's Section 3 sensitivity curves");
  ComputeSensitivity(in, &an);
  return an;
}

}  // namespace kincal
