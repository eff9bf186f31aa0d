#include "diagnose/clearance.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "calib/calibrate.h"
#include "calib/chain.h"
#include "calib/model_state.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/svg_plot.h"
#include "data/yaml_util.h"

namespace kincal {
namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// eps for measurement m with joint j's reading offset by `offset_internal`.
double SweptError(const ModelState& state, const Measurement& m, int joint,
                  double offset_internal) {
  Measurement moved = m;
  moved.input.q[joint] += offset_internal;
  return Residual(state, moved).norm();
}

SweepCurve Sweep(const ModelState& state, const Measurement& m, int joint,
                 const ClearanceOptions& options) {
  const Chain& chain = state.chain;
  SweepCurve c;
  c.joint = joint;
  const int n = options.steps_per_side;
  for (int k = -n; k <= n; ++k) {
    const double offset = options.gamma * k / n;
    c.offset.push_back(offset);
    c.error_mm.push_back(SweptError(state, m, joint,
                                    chain.ReadingToInternal(joint, offset) -
                                        chain.ReadingToInternal(joint, 0)));
  }
  c.error_before_mm = c.error_mm[n];
  const int best =
      static_cast<int>(std::min_element(c.error_mm.begin(), c.error_mm.end()) -
                       c.error_mm.begin());
  c.error_min_mm = c.error_mm[best];
  c.at_offset = c.offset[best];
  // Parabola through the grid minimum and its neighbours.
  if (best > 0 && best < 2 * n) {
    const double y0 = c.error_mm[best - 1], y1 = c.error_mm[best],
                 y2 = c.error_mm[best + 1];
    const double denom = y0 - 2 * y1 + y2;
    if (denom > 0) {
      const double h = options.gamma / n;
      const double shift = 0.5 * h * (y0 - y2) / denom;
      const double x = c.at_offset + shift;
      const double y = SweptError(state, m, joint,
                                  chain.ReadingToInternal(joint, x) -
                                      chain.ReadingToInternal(joint, 0));
      if (y < c.error_min_mm) {
        c.error_min_mm = y;
        c.at_offset = x;
      }
    }
  }
  return c;
}

}  // namespace

void ClearanceOptions::Check() const {
  Require(std::isfinite(gamma) && gamma > 0,
          "--gamma must be > 0, got " + std::to_string(gamma));
  Require(steps_per_side >= 2, "steps per side must be >= 2");
  Require(worst_poses >= 1, "worst poses must be >= 1");
  Require(reduction_threshold > 0 && reduction_threshold < 1,
          "reduction threshold must be in (0, 1)");
}

ClearanceResult DiagnoseClearance(const Robot& robot, const Observations& obs,
                                  const ClearanceOptions& options) {
  options.Check();
  ModelState state;
  if (options.calibrate_geometry) {
    CalibrateOptions co;
    co.holdout_fraction = 0.0;
    state.chain = Chain::FromRobot(Calibrate(robot, obs, co).calibrated);
  } else {
    state.chain = Chain::FromRobot(robot);
  }
  std::vector<Measurement> all = MakeMeasurements(state.chain, obs, &state);
  std::vector<Measurement> ms;
  for (const Measurement& m : all) {
    if (m.kind == Measurement::kMeasured) ms.push_back(m);
  }
  const int distinct = DistinctPoses(ms);
  if (distinct < 3) {
    throw InputError(obs.source, 0, 0,
                     "the clearance test needs measured tip points (x, y, z) "
                     "at >= 3 distinct poses to estimate the measuring frame; "
                     "found " +
                         std::to_string(distinct));
  }
  // The measuring frame first, robot held as given.
  InitializeFrameAndPoints(ms, &state);
  FitOptions frame;
  frame.free = FrameParams();
  frame.compute_covariance = false;
  Fit(ms, frame, &state);

  ClearanceResult r;
  r.gamma = options.gamma;
  const int nj = state.chain.num_joints();
  for (int j = 0; j < nj; ++j) {
    r.joint_names.push_back(state.chain.rows[j].name);
    r.joint_units.push_back(
        state.chain.rows[j].type == JointType::kPrismatic ? "mm" : "deg");
  }
  for (const Measurement& m : ms) {
    r.rows.push_back(m.row);
    r.poses.push_back(obs.rows[m.row].pose);
    r.errors_mm.push_back(Residual(state, m).norm());
  }
  r.stats = ComputeErrorStats(r.errors_mm);

  std::vector<int> order(ms.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return r.errors_mm[a] > r.errors_mm[b];
  });
  const int examined =
      std::min(options.worst_poses, static_cast<int>(order.size()));
  r.wins.assign(nj, 0);
  std::vector<std::vector<double>> ratios(nj);
  for (int k = 0; k < examined; ++k) {
    const Measurement& m = ms[order[k]];
    PoseSweep ps;
    ps.row = m.row;
    ps.pose = obs.rows[m.row].pose;
    ps.error_mm = r.errors_mm[order[k]];
    double best = std::numeric_limits<double>::infinity();
    for (int j = 0; j < nj; ++j) {
      ps.joints.push_back(Sweep(state, m, j, options));
      const SweepCurve& c = ps.joints.back();
      ratios[j].push_back(
          c.error_before_mm > 0 ? c.error_min_mm / c.error_before_mm : 1.0);
      if (c.error_min_mm < best) {
        best = c.error_min_mm;
        ps.best_joint = j;
      }
    }
    if (ps.best_joint >= 0) ++r.wins[ps.best_joint];
    r.sweeps.push_back(ps);
  }
  for (int j = 0; j < nj; ++j) r.median_ratio.push_back(Median(ratios[j]));
  // Suspect: the joint whose sweeps reduce the examined poses' errors most
  // (smallest median error_min / error_before), provided that reduction is
  // clear and no other joint was the best joint at more poses.
  const int most_wins = *std::max_element(r.wins.begin(), r.wins.end());
  int best_joint = -1;
  for (int j = 0; j < nj; ++j) {
    if (best_joint < 0 || r.median_ratio[j] < r.median_ratio[best_joint]) {
      best_joint = j;
    }
  }
  if (best_joint >= 0 && r.wins[best_joint] == most_wins &&
      r.median_ratio[best_joint] <= options.reduction_threshold) {
    r.suspect = best_joint;
  }
  return r;
}

nlohmann::json ClearanceJson(const ClearanceResult& r) {
  nlohmann::json j;
  auto num = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  const PoseSweep* worst = r.sweeps.empty() ? nullptr : &r.sweeps[0];
  j["worst_pose"] =
      worst ? nlohmann::json(worst->pose) : nlohmann::json(nullptr);
  j["worst_error_mm"] = worst ? num(worst->error_mm) : nlohmann::json(nullptr);
  j["gamma"] = r.gamma;
  nlohmann::json joints = nlohmann::json::array();
  if (worst) {
    for (const SweepCurve& c : worst->joints) {
      joints.push_back({{"joint", r.joint_names[c.joint]},
                        {"unit", r.joint_units[c.joint]},
                        {"error_before_mm", num(c.error_before_mm)},
                        {"error_min_mm", num(c.error_min_mm)},
                        {"at_offset", num(c.at_offset)},
                        {"wins", r.wins[c.joint]},
                        {"median_ratio", num(r.median_ratio[c.joint])}});
    }
  }
  j["joints"] = joints;
  j["suspect"] = r.suspect >= 0 ? nlohmann::json(r.joint_names[r.suspect])
                                : nlohmann::json(nullptr);
  nlohmann::json examined = nlohmann::json::array();
  for (const PoseSweep& ps : r.sweeps) {
    nlohmann::json per = nlohmann::json::array();
    for (const SweepCurve& c : ps.joints) {
      per.push_back({{"joint", r.joint_names[c.joint]},
                     {"error_min_mm", num(c.error_min_mm)},
                     {"at_offset", num(c.at_offset)},
                     {"offsets", c.offset},
                     {"errors_mm", c.error_mm}});
    }
    examined.push_back(
        {{"pose", ps.pose},
         {"error_mm", num(ps.error_mm)},
         {"best_joint", ps.best_joint >= 0
                            ? nlohmann::json(r.joint_names[ps.best_joint])
                            : nlohmann::json(nullptr)},
         {"curves", per}});
  }
  j["examined_poses"] = examined;
  nlohmann::json dev = nlohmann::json::array();
  for (size_t i = 0; i < r.poses.size(); ++i) {
    dev.push_back({{"pose", r.poses[i]}, {"error_mm", num(r.errors_mm[i])}});
  }
  j["deviations"] = dev;
  j["rms_mm"] = num(r.stats.rms_mm);
  j["max_mm"] = num(r.stats.max_mm);
  return j;
}

std::string ClearanceCsv(const ClearanceResult& r) {
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  os << "kind,pose,joint,offset,error_mm\n";
  for (size_t i = 0; i < r.poses.size(); ++i) {
    os << "deviation," << CsvQuote(r.poses[i]) << ",,,"
       << FormatDouble(r.errors_mm[i]) << "\n";
  }
  for (const PoseSweep& ps : r.sweeps) {
    for (const SweepCurve& c : ps.joints) {
      for (size_t k = 0; k < c.offset.size(); ++k) {
        os << "sweep," << CsvQuote(ps.pose) << "," << r.joint_names[c.joint]
           << "," << FormatDouble(c.offset[k]) << ","
           << FormatDouble(c.error_mm[k]) << "\n";
      }
    }
  }
  return os.str();
}

Plot DeviationPlot(const ClearanceResult& r) {
  Plot deviations;
  deviations.title = "Joint motion error test: deviation per pose (Fig. 4)";
  deviations.x_label = "pose (visit order)";
  deviations.y_label = "eps_i (mm)";
  PlotSeries bars;
  bars.label = "eps_i";
  bars.bars = true;
  for (size_t i = 0; i < r.errors_mm.size(); ++i) {
    bars.x.push_back(static_cast<double>(i + 1));
    bars.y.push_back(r.errors_mm[i]);
  }
  deviations.series.push_back(bars);
  deviations.lines.push_back({r.stats.rms_mm, "RMS"});
  return deviations;
}

Plot SweepPlot(const ClearanceResult& r, size_t k) {
  Plot curves;
  curves.x_label = "reading offset (deg | mm)";
  curves.y_label = "eps (mm)";
  if (k >= r.sweeps.size()) {
    curves.title = "no pose examined";
    return curves;
  }
  const PoseSweep& ps = r.sweeps[k];
  curves.title = (k == 0 ? "Sweep of each joint at the worst pose "
                         : "Sweep of each joint at pose ") +
                 ps.pose + (k == 0 ? " (Fig. 5)" : "");
  if (ps.error_mm > 0) {
    curves.y_min = 0.0;
    curves.y_max = 3.0 * ps.error_mm;
    curves.y_label = "eps (mm), clipped at 3x the pose's error";
    curves.lines.push_back({ps.error_mm, "error before"});
  }
  for (const SweepCurve& c : ps.joints) {
    PlotSeries s;
    s.label = r.joint_names[c.joint] + " (" + r.joint_units[c.joint] + ")";
    s.x = c.offset;
    s.y = c.error_mm;
    curves.series.push_back(s);
  }
  return curves;
}

std::string ClearanceSvg(const ClearanceResult& r) {
  return FormatSvgPlots({DeviationPlot(r), SweepPlot(r, 0)});
}

}  // namespace kincal
