#include "report/verdict.h"

#include <cmath>
#include <sstream>

#include "calib/outliers.h"
#include "report/html.h"

namespace kincal {
namespace {

double Num(const nlohmann::json& object, const char* key) {
  return object.is_object() && object.contains(key) && object[key].is_number()
             ? object[key].get<double>()
             : NAN;
}

double At(const nlohmann::json& array, size_t k) {
  return array.is_array() && k < array.size() && array[k].is_number()
             ? array[k].get<double>()
             : NAN;
}

std::string Percent(double fraction) { return Fmt(100 * fraction, 2) + " %"; }

// "0.344 mm (held out: ...)" plus a warning when the figure rests on few
// poses.
std::string Quote(const HeldOutFigure& h) {
  std::string s = Fmt(h.rms_mm, 3) + " mm (" + h.source + ")";
  if (h.n > 0 && h.n < kMinHeldOutPoses) {
    s += " - only " + std::to_string(h.n) + " held-out poses: a rough figure";
  }
  return s;
}

HeldOutFigure DiagnosisHeldOut(const nlohmann::json& diag, const char* model) {
  HeldOutFigure h;
  if (!diag.contains(model)) return h;
  h.rms_mm = Num(diag[model], "heldout_rms_mm");
  h.known = std::isfinite(h.rms_mm);
  h.n = static_cast<int>(Num(diag, "heldout_poses"));
  const double fraction = Num(diag, "holdout_fraction");
  h.source =
      "held out: " +
      (std::isfinite(fraction) ? Fmt(100 * fraction, 3) + " % of " : "") +
      "poses (" + std::to_string(h.n) + ") by diagnose model";
  return h;
}

HeldOutFigure BundleHeldOut(const nlohmann::json& bundle) {
  HeldOutFigure h;
  h.rms_mm = Num(bundle, "heldout_tip_rms_mm");
  h.known = std::isfinite(h.rms_mm);
  const double tips = Num(bundle, "heldout_tips");
  h.n = std::isfinite(tips) ? static_cast<int>(tips) : 0;
  h.source = "held out: " + std::to_string(h.n) + " tips of " +
             Fmt(Num(bundle, "heldout_frames"), 4) + " frames by kincal bundle";
  return h;
}

HeldOutFigure CalibrationHeldOut(const ReportAnalysis& an,
                                 const ReportOptions& opt) {
  HeldOutFigure h;
  if (!an.has_calres) return h;
  h.known = true;
  h.rms_mm = an.calres.heldout.rms_mm;
  h.n = an.calres.heldout.n;
  h.source = "held out: 20 % of poses (" + std::to_string(h.n) +
             ") by this report's calibration, seed " + std::to_string(opt.seed);
  return h;
}

std::vector<std::string> DiagnosisWords(const ReportInputs& in,
                                        const ReportAnalysis& an,
                                        const ReportOptions& opt) {
  const nlohmann::json& d = in.diag;
  const bool found =
      d.value("verdict", "") == "effect_found" && !d["findings"].empty();
  std::ostringstream head;
  head << (found ? "Diagnosis: effect found. "
                 : "Diagnosis: no significant effect (no cause tested "
                   "lowered the error on held-out poses). ");
  const HeldOutFigure geo = GeometricHeldOut(in, an, opt);
  const HeldOutFigure fin = DiagnosisHeldOut(d, "final");
  if (geo.known && found && fin.known) {
    head << "Held-out error " << Fmt(geo.rms_mm, 3)
         << " mm with the calibrated geometry -> " << Quote(fin)
         << " with the model extensions.";
  } else if (geo.known) {
    head << "Held-out error with the calibrated geometry " << Quote(geo) << ".";
  }
  std::vector<std::string> out = {head.str()};
  for (const auto& f : d["findings"]) {
    std::ostringstream s;
    const std::string cause = f.value("cause", "?");
    if (cause == "unexplained") {
      s << "unexplained systematic error, RMS " << Fmt(Num(f, "magnitude"), 3)
        << " mm";
      std::string dep;
      if (f.contains("depends_on") && f["depends_on"].is_array()) {
        for (const auto& x : f["depends_on"]) {
          if (x.is_string())
            dep += (dep.empty() ? "" : ", ") + x.get<std::string>();
        }
      }
      if (!dep.empty()) s << " depending on " << dep;
    } else {
      const std::string joint = f.contains("joint") && f["joint"].is_string()
                                    ? f["joint"].get<std::string>()
                                    : "";
      s << cause << (joint.empty() ? "" : " in " + joint) << ", "
        << Fmt(Num(f, "magnitude"), 3) << " " << f.value("unit", "");
      if (f.contains("ci95") && f["ci95"].size() == 2) {
        s << " [" << Fmt(At(f["ci95"], 0), 3) << ", "
          << Fmt(At(f["ci95"], 1), 3) << "] (95 %)";
      }
    }
    out.push_back(s.str());
  }
  return out;
}

std::string BundleWords(const ReportInputs& in, const ReportOptions& opt) {
  const nlohmann::json& b = in.bundle;
  std::ostringstream s;
  s << "Bundle adjustment (kincal bundle, " << opt.bundle
    << "): held-out tip error " << Quote(BundleHeldOut(b))
    << "; reprojection RMS " << Fmt(Num(b, "reproj_rms_px"), 3)
    << " px (training), " << Fmt(Num(b, "heldout_reproj_rms_px"), 3)
    << " px (held out); sigma0 " << Fmt(Num(b, "sigma0_px"), 3) << " px. ";
  const size_t held =
      b.contains("unidentifiable") ? b["unidentifiable"].size() : 0;
  s << (b.contains("params") ? b["params"].size() : 0)
    << " robot parameters estimated, " << held
    << " held at nominal (see Identifiability).";
  if (b.contains("findings") && b["findings"].is_array()) {
    for (const auto& f : b["findings"]) {
      s << " Found: " << f.value("cause", "?") << " in "
        << f.value("joint", "?") << ", " << Fmt(Num(f, "magnitude"), 3);
      if (f.contains("ci95") && f["ci95"].size() == 2) {
        s << " [" << Fmt(At(f["ci95"], 0), 3) << ", "
          << Fmt(At(f["ci95"], 1), 3) << "]";
      }
      s << ".";
    }
  }
  return s.str();
}

std::string CalibrationWords(const ReportInputs& in, const ReportAnalysis& an,
                             const ReportOptions& opt) {
  const CalibrateResult& c = an.calres;
  std::ostringstream s;
  s << "Geometric calibration (run here, seed " << opt.seed << "): ";
  if (in.has_diag) {
    s << "training RMS " << Fmt(c.train.rms_mm, 3)
      << " mm (its held-out figure is the diagnosis' above)";
  } else {
    s << "held-out RMS " << Quote(CalibrationHeldOut(an, opt)) << ", training "
      << Fmt(c.train.rms_mm, 3) << " mm";
  }
  if (an.has_nominal) {
    s << "; the nominal robot, frame registered only: "
      << Fmt(an.res_nominal.stats.rms_mm, 3) << " mm";
  }
  s << ". " << c.identifiability.RobotParameterCount()
    << " robot parameters identifiable; "
    << c.identifiability.unidentifiable.size()
    << " others are redundant with them or the frame and stay at nominal "
       "(see Identifiability).";
  return s.str();
}

// Gross errors (calib/outliers.h): named in words, the poses first.
std::string OutlierWords(const CalibrateResult& c) {
  std::ostringstream g;
  g << c.outliers.size() << " row(s) are more than "
    << Fmt(kDefaultOutlierSigmas, 2) << " robust sigmas ("
    << Fmt(c.outlier_axis_sigma_mm, 3)
    << " mm per axis) off the calibrated model"
    << (c.outliers_too_many
            ? " (too many to leave them all out: the model may be wrong "
              "rather than the rows)"
            : " and were left out of the fit")
    << ":";
  for (size_t i = 0; i < c.outliers.size() && i < 10; ++i) {
    const RowOutlier& o = c.outliers[i];
    g << (i ? ";" : "") << " pose " << o.pose << ": " << Fmt(o.error_mm, 3)
      << " mm" << (o.heldout ? ", held out" : "")
      << (o.excluded ? "" : ", kept");
    if (!o.near_point.empty()) {
      g << " (" << Fmt(o.near_point_mm, 3) << " mm from " << o.near_point
        << ": saved under the wrong label?)";
    }
  }
  if (c.outliers.size() > 10) g << "; ...";
  g << ". Check these rows of the data.";
  return g.str();
}

std::string ClearanceWords(const ReportAnalysis& an, const ReportOptions& opt) {
  const ClearanceResult& c = an.clear;
  return "Section 4 test (sweep +-" + Fmt(opt.gamma, 3) +
         " of each joint at the " + std::to_string(c.sweeps.size()) +
         " worst poses): " +
         (c.suspect >= 0 ? "suspect joint " + c.joint_names[c.suspect] + "."
                         : "no joint removes the error of the worst poses.");
}

// camcal's figures per camera and its worst view, in one sentence.
std::string CameraWords(const nlohmann::json& camcal) {
  std::ostringstream s;
  s << "Cameras (kincal camcal):";
  int worst_view = 0;
  double worst = -1;
  std::string worst_camera;
  bool first = true;
  for (const auto& c : camcal["cameras"]) {
    s << (first ? " " : "; ") << c.value("name", "?") << " RMS "
      << Fmt(Num(c, "rms_px"), 3) << " px (held out "
      << Fmt(Num(c, "holdout_rms_px"), 3) << " px)";
    first = false;
    if (!c.contains("view_rms_px") || !c["view_rms_px"].is_array()) continue;
    for (size_t v = 0; v < c["view_rms_px"].size(); ++v) {
      const double e = At(c["view_rms_px"], v);
      if (e > worst) {
        worst = e, worst_view = static_cast<int>(v) + 1;
        worst_camera = c.value("name", "?");
      }
    }
  }
  s << ".";
  if (worst >= 0) {
    s << " Worst view: " << worst_view << " (" << worst_camera << ", "
      << Fmt(worst, 3) << " px).";
  }
  return s.str();
}

}  // namespace

HeldOutFigure GeometricHeldOut(const ReportInputs& in, const ReportAnalysis& an,
                               const ReportOptions& opt) {
  if (in.has_diag) {
    const HeldOutFigure h = DiagnosisHeldOut(in.diag, "nominal");
    if (h.known) return h;
  }
  if (in.has_bundle) return BundleHeldOut(in.bundle);
  return CalibrationHeldOut(an, opt);
}

HeldOutFigure FinalHeldOut(const ReportInputs& in, const ReportAnalysis& an,
                           const ReportOptions& opt) {
  if (in.has_diag && in.diag.value("verdict", "") == "effect_found") {
    const HeldOutFigure h = DiagnosisHeldOut(in.diag, "final");
    if (h.known) return h;
  }
  return GeometricHeldOut(in, an, opt);
}

double ChiSquareQuantile(double p, double dof) {
  // Standard normal quantile (Acklam's rational approximation, central
  // part; p in [0.02425, 0.97575] covers the 95 % interval).
  const double q = p - 0.5, r = q * q;
  const double z =
      (((((-3.969683028665376e+01 * r + 2.209460984245205e+02) * r -
          2.759285104469687e+02) *
             r +
         1.383577518672690e+02) *
            r -
        3.066479806614716e+01) *
           r +
       2.506628277459239e+00) *
      q /
      (((((-5.447609879822406e+01 * r + 1.615858368580409e+02) * r -
          1.556989798598866e+02) *
             r +
         6.680131188771972e+01) *
            r -
        1.328068155288572e+01) *
           r +
       1.0);
  const double a = 2.0 / (9.0 * dof);
  const double t = 1.0 - a + z * std::sqrt(a);
  return dof * t * t * t;
}

ToleranceCheck CheckTolerance(const ReportInputs& in, const ReportAnalysis& an,
                              const ReportOptions& opt) {
  ToleranceCheck t;
  t.given = opt.tolerance_mm > 0;
  if (!t.given) return t;
  t.tolerance_mm = opt.tolerance_mm;
  t.heldout = FinalHeldOut(in, an, opt);
  t.available = t.heldout.known && t.heldout.n > 0;
  if (!t.available) {
    t.words = "Tolerance " + Fmt(t.tolerance_mm, 3) +
              " mm: no held-out error to test it against (give robot and "
              "observations, a diagnosis or a bundle result).";
    return t;
  }
  if (t.heldout.n < kMinHeldOutPoses) {
    t.words = "NOT DECIDED: tolerance " + Fmt(t.tolerance_mm, 3) +
              " mm, held-out RMS " + Fmt(t.heldout.rms_mm, 3) + " mm (" +
              t.heldout.source + "): too few held-out poses (" +
              std::to_string(t.heldout.n) + "; at least " +
              std::to_string(kMinHeldOutPoses) + " are needed to decide).";
  }
  const double dof = 3.0 * t.heldout.n;  // 3 components per held-out pose
  const double ss = t.heldout.rms_mm * t.heldout.rms_mm * dof;
  t.lo_mm = std::sqrt(ss / ChiSquareQuantile(0.975, dof));
  t.hi_mm = std::sqrt(ss / ChiSquareQuantile(0.025, dof));
  if (t.heldout.n < kMinHeldOutPoses) return t;  // words set above
  t.decided = true;
  t.pass = t.hi_mm <= t.tolerance_mm;
  const std::string figure =
      "held-out RMS " + Fmt(t.heldout.rms_mm, 3) + " mm, 95 % interval [" +
      Fmt(t.lo_mm, 3) + ", " + Fmt(t.hi_mm, 3) + "] mm (" + t.heldout.source +
      "; chi-square with " + std::to_string(static_cast<int>(dof)) +
      " residual components)";
  if (t.pass) {
    t.words = "PASS: " + figure + " is within the tolerance of " +
              Fmt(t.tolerance_mm, 3) + " mm.";
  } else if (t.lo_mm > t.tolerance_mm) {
    t.words = "FAIL: " + figure + " is above the tolerance of " +
              Fmt(t.tolerance_mm, 3) + " mm.";
  } else {
    t.words = "FAIL (not shown to pass): " + figure +
              " reaches above the tolerance of " + Fmt(t.tolerance_mm, 3) +
              " mm; more held-out poses would narrow it.";
  }
  return t;
}

std::string StructureSentence(const ReportInputs& in,
                              const ReportAnalysis& an) {
  const StructureShare& s = an.structure;
  if (s.a < 0) return "";
  const Robot& jr = in.JointRobot();
  const std::string a = jr.joints[s.a].name, b = jr.joints[s.b].name;
  std::ostringstream out;
  out << "What the geometric model still gets wrong (RMS "
      << Fmt(an.res_geo.stats.rms_mm, 3) << " mm on " << s.poses
      << " poses) depends most on " << a << " x " << b;
  const bool shares_ok = s.poses >= kMinPosesForShares && s.pair >= 0 &&
                         s.pair <= 1 && s.a_alone >= 0 && s.a_alone <= 1 &&
                         s.b_alone >= 0 && s.b_alone <= 1;
  if (!shares_ok) {
    out << ", but there are too few poses (" << s.poses << ") to say how much "
        << "of it they explain: a 5 x 5 grid of two joints needs about "
        << kMinPosesForShares << " poses before its share means more than "
        << "chance.";
    return out.str();
  }
  out << ": their 5 x 5 grid explains " << Percent(s.pair)
      << " of the variance of the 3D error vectors (" << a << " alone "
      << Percent(s.a_alone) << ", " << b << " alone " << Percent(s.b_alone)
      << "; by chance ~" << Percent(ChanceShare(s.poses)) << ").";
  if (s.with_extensions >= 0 && s.with_extensions <= 1) {
    out << " With the extensions: " << Percent(s.with_extensions) << ".";
  }
  return out.str();
}

std::vector<std::string> WriteVerdict(const ReportInputs& in,
                                      const ReportAnalysis& an,
                                      const ReportOptions& opt) {
  std::vector<std::string> v;
  const ToleranceCheck tol = CheckTolerance(in, an, opt);
  if (tol.given) v.push_back(tol.words);
  if (in.has_diag) {
    for (const auto& p : DiagnosisWords(in, an, opt)) v.push_back(p);
  }
  if (in.has_bundle) {
    v.push_back(BundleWords(in, opt));
  } else if (in.cal_header.found) {
    v.push_back("The calibrated robot (" + opt.calibrated +
                ") was made by kincal bundle" +
                (in.cal_header.reprojection.empty()
                     ? ""
                     : " (" + in.cal_header.reprojection + ")") +
                ". Give what `kincal bundle --json` printed with --bundle to "
                "see its held-out tip error and sigma here; the calibration "
                "below is of the observed points, run by this report.");
  }
  if (an.has_calres) {
    v.push_back(CalibrationWords(in, an, opt));
    if (!an.calres.outliers.empty()) v.push_back(OutlierWords(an.calres));
  }
  if (an.has_ext) {
    v.push_back("The extended model (" + opt.calibrated + ", " +
                std::to_string(in.cal.extensions.size()) +
                " extensions) on all poses: RMS " +
                Fmt(an.res_ext.stats.rms_mm, 3) + " mm (geometry alone " +
                Fmt(an.res_geo.stats.rms_mm, 3) + " mm).");
  }
  const std::string structure = StructureSentence(in, an);
  if (!structure.empty()) v.push_back(structure);
  if (an.has_clear) v.push_back(ClearanceWords(an, opt));
  if (in.camcal.is_object() && in.camcal.contains("cameras") &&
      in.camcal["cameras"].is_array()) {
    v.push_back(CameraWords(in.camcal));
  }
  if (v.empty()) {
    v.push_back(
        "No robot data given: the sections below show what the inputs hold.");
  }
  return v;
}

}  // namespace kincal
