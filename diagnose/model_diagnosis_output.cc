// The outputs of `kincal diagnose model` (declared in model_diagnosis.h):
// the spec's diagnosis JSON with the project's added fields, and the
// residual CSV of --residuals. Apart from the selection procedure so that
// model_diagnosis.cc stays the method.
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "data/csv.h"
#include "data/provenance.h"
#include "data/yaml_util.h"
#include "diagnose/catalogue.h"
#include "diagnose/model_diagnosis.h"

namespace kincal {

namespace {
nlohmann::json Num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
// Internal causes cyclic2 / cyclic3 are the spec's cyclic at a higher
// harmonic: reported as cause "cyclic" with "harmonic" 2 or 3.
std::string SpecCause(const std::string& cause) { return SpecCauseName(cause); }
nlohmann::json TermsOrNull(const std::string& cause) {
  const int t = TransmissionTerms(cause);
  return t > 0 ? nlohmann::json(t) : nlohmann::json(nullptr);
}
nlohmann::json HarmonicOrNull(const std::string& cause) {
  const int h = CyclicHarmonic(cause);
  return h > 0 ? nlohmann::json(h) : nlohmann::json(nullptr);
}

nlohmann::json JointOrNull(const std::string& joint) {
  return joint.empty() ? nlohmann::json(nullptr) : nlohmann::json(joint);
}
}  // namespace

nlohmann::json DiagnosisJson(const DiagnosisResult& r,
                             const DiagnoseOptions& options) {
  nlohmann::json findings = nlohmann::json::array();
  for (const Finding& f : r.findings) {
    nlohmann::json eq = nlohmann::json::array();
    for (const Equivalent& e : f.equivalent) {
      eq.push_back({{"cause", SpecCause(e.cause)},
                    {"harmonic", HarmonicOrNull(e.cause)},
                    {"terms", TermsOrNull(e.cause)},
                    {"joint", JointOrNull(e.joint)},
                    {"magnitude", Num(e.magnitude)},
                    {"unit", e.unit},
                    {"train_rms_mm", Num(e.train_rms_mm)},
                    {"heldout_rms_mm", Num(e.heldout_rms_mm)}});
    }
    findings.push_back(
        {{"cause", SpecCause(f.cause)},
         {"harmonic", HarmonicOrNull(f.cause)},
         {"terms", TermsOrNull(f.cause)},
         {"joint", JointOrNull(f.joint)},
         {"magnitude", Num(f.magnitude)},
         {"unit", f.unit},
         {"ci95", {Num(f.ci_low), Num(f.ci_high)}},
         {"heldout_rms_before_mm", Num(f.heldout_rms_before_mm)},
         {"heldout_rms_after_mm", Num(f.heldout_rms_after_mm)},
         {"train_rms_after_mm", Num(f.train_rms_after_mm)},
         {"validation_rms_before_mm", Num(f.validation_rms_before_mm)},
         {"validation_rms_after_mm", Num(f.validation_rms_after_mm)},
         {"cv_rms_before_mm", Num(f.cv_rms_before_mm)},
         {"cv_rms_after_mm", Num(f.cv_rms_after_mm)},
         {"f", Num(f.f)},
         {"p_value", Num(f.p_value)},
         {"equivalent", eq}});
    if (f.periodic) {
      nlohmann::json arcs = nlohmann::json::array();
      for (const auto& a : f.extrapolated) arcs.push_back({a[0], a[1]});
      findings.back()["periodic"] = {
          {"travel_deg", {f.travel_lo, f.travel_hi}},
          {"extrapolated_deg", arcs},
          {"amplitude_deg", Num(f.amplitude)},
          {"extrapolated_peak_deg", Num(f.extrapolated_peak)}};
    }
    if (f.cause == "unexplained") {
      nlohmann::json single = nlohmann::json::object();
      for (const auto& kv : f.single_inputs) single[kv.first] = Num(kv.second);
      findings.back()["depends_on"] = f.depends_on;
      findings.back()["smooth_correction"] = {
          {"method",
           "k-nearest-neighbour regression, k and inputs by 5-fold "
           "cross-validation"},
          {"k", f.smooth_k},
          {"cv_explained", Num(f.cv_explained)},
          {"single_input_cv_explained", single},
          {"measured_point_cv_explained", Num(f.point_cv_explained)}};
    }
  }
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& step : r.steps) {
    nlohmann::json table = nlohmann::json::array();
    for (const CandidateScore& c : step) {
      table.push_back({{"cause", SpecCause(c.cause)},
                       {"harmonic", HarmonicOrNull(c.cause)},
                       {"terms", TermsOrNull(c.cause)},
                       {"joint", JointOrNull(c.joint)},
                       {"identifiable", c.identifiable},
                       {"parameters", c.k},
                       {"train_rms_mm", Num(c.train_rms_mm)},
                       {"heldout_rms_mm", Num(c.heldout_rms_mm)},
                       {"f", Num(c.f)},
                       {"p_value", Num(c.p_value)},
                       {"significant", c.significant},
                       {"validation_rms_mm", Num(c.validation_rms_mm)},
                       {"cv_rms_mm", Num(c.cv_rms_mm)},
                       {"cv_z", Num(c.cv_z)},
                       {"magnitude", Num(c.magnitude)},
                       {"unit", c.unit}});
    }
    steps.push_back(table);
  }
  nlohmann::json j;
  j["verdict"] = r.verdict;
  j["nominal"] = {{"train_rms_mm", Num(r.nominal_train_rms_mm)},
                  {"heldout_rms_mm", Num(r.nominal_heldout_rms_mm)},
                  {"cv_rms_mm", Num(r.nominal_cv_rms_mm)}};
  j["findings"] = findings;
  j["validation"] = {{"series", options.validation.size()},
                     {"nominal_rms_mm", Num(r.nominal_validation_rms_mm)},
                     {"final_rms_mm", Num(r.final_validation_rms_mm)}};
  j["final"] = {{"heldout_rms_mm", Num(r.final_heldout_rms_mm)},
                {"train_rms_mm", Num(r.final_train_rms_mm)},
                {"cv_rms_mm", Num(r.final_cv_rms_mm)}};
  j["folds"] = r.folds;
  j["cross_validation"] = {
      {"folds", r.folds},
      {"selection", r.folds >= 2
                        ? "k-fold cross-validated RMS of the training poses"
                        : "single held-out split"},
      {"fold_fit", options.cv_refit ? "refit" : "linearised"},
      {"nominal_rms_mm", Num(r.nominal_cv_rms_mm)},
      {"final_rms_mm", Num(r.final_cv_rms_mm)}};
  j["train_poses"] = r.train_poses;
  j["heldout_poses"] = r.heldout_poses;
  j["noise_mm"] = Num(r.noise_mm);
  j["noise_source"] = r.noise_source;
  j["residual_sigma_mm"] = Num(r.residual_sigma_mm);
  j["systematic_rms_mm"] = Num(r.systematic_rms_mm);
  j["false_alarm"] = options.false_alarm;
  j["bonferroni_alpha"] = Num(r.bonferroni_alpha);
  j["not_identifiable"] = r.not_identifiable;
  j["steps"] = steps;
  j["seed"] = options.seed;
  j["holdout_fraction"] = options.holdout_fraction;
  j["seconds"] = r.seconds;
  return j;
}

std::string ResidualsCsv(const DiagnosisResult& r, const Observations& obs) {
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  os << "# residual = final model (all poses) - measured, measuring frame\n";
  os << "pose,set,dx_mm,dy_mm,dz_mm,error_mm\n";
  for (size_t i = 0; i < r.rows.size(); ++i) {
    const Eigen::Vector3d& e = r.residuals[i];
    os << CsvQuote(obs.rows[r.rows[i]].pose) << ","
       << (r.heldout[i] ? "heldout" : "train") << "," << FormatDouble(e.x())
       << "," << FormatDouble(e.y()) << "," << FormatDouble(e.z()) << ","
       << FormatDouble(e.norm()) << "\n";
  }
  return os.str();
}

}  // namespace kincal
