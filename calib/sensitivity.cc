#include "calib/sensitivity.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "calib/identifiability.h"
#include "calib/paper_method.h"
#include "data/error.h"
#include "data/minimize.h"

namespace kincal {

void SensitivityOptions::Check() const {
  Require(range > 0 && std::isfinite(range),
          "--range must be a positive number of units (mm or deg)");
  Require(steps >= 3 && steps % 2 == 1,
          "--steps must be odd and >= 3 (0 offset on the grid)");
  Require(eta_mm > 0 && std::isfinite(eta_mm), "--eta must be positive (mm)");
  Require(valley_tolerance_mm >= 0 && valley_tolerance_fraction >= 0,
          "valley tolerances must be >= 0");
}

namespace {

// eps with parameter p at value (internal units).
double EpsAt(ModelState* state, const std::vector<Measurement>& ms,
             const ParamInfo& p, double value) {
  double* addr = ParamAddress(state, p);
  const double saved = *addr;
  *addr = value;
  const double eps = PaperEpsilon(*state, ms);
  *addr = saved;
  return eps;
}

std::string Join(const std::vector<std::string>& names, size_t max = 8) {
  std::string out;
  for (size_t i = 0; i < names.size() && i < max; ++i) {
    out += (i ? ", " : "") + names[i];
  }
  if (names.size() > max) out += ", ...";
  return out;
}

// The fixed-point rows of `obs` (the criterion's data); `count` gets the
// poses per fixed point. InputError when no fixed point has 2 poses.
std::vector<Measurement> FixedPointRows(const Observations& obs,
                                        ModelState* state,
                                        std::vector<int>* count) {
  const std::vector<Measurement> all =
      MakeMeasurements(state->chain, obs, state);
  std::vector<Measurement> ms;
  for (const Measurement& m : all) {
    if (m.kind == Measurement::kFixedPoint) ms.push_back(m);
  }
  count->assign(state->point_labels.size(), 0);
  for (const Measurement& m : ms) ++(*count)[m.point];
  if (std::none_of(count->begin(), count->end(),
                   [](int c) { return c >= 2; })) {
    throw InputError(obs.source, 0, 0,
                     "the sensitivity criterion needs fixed_point rows: at "
                     "least one fixed point held in 2 or more poses");
  }
  return ms;
}

// The parameters the data cannot determine at this solution (points set to
// the centroids, so that the Jacobian is taken where the model fits).
std::vector<std::string> UnidentifiableAtCentroids(
    const std::vector<Measurement>& ms, const std::vector<int>& count,
    const std::vector<ParamInfo>& params, ModelState* state) {
  std::vector<Eigen::Vector3d> sum(state->point_labels.size(),
                                   Eigen::Vector3d::Zero());
  for (const Measurement& m : ms)
    sum[m.point] += TipInBase(state->chain, m.input);
  for (size_t k = 0; k < sum.size(); ++k) {
    if (count[k] == 0) continue;
    for (int a = 0; a < 3; ++a)
      state->points_in_base[k][a] = sum[k][a] / count[k];
  }
  std::vector<ParamInfo> candidates = PointParams(*state);
  for (const ParamInfo& p : params) candidates.push_back(p);
  const Identifiability id = AnalyzeIdentifiability(ms, *state, candidates);
  std::vector<std::string> out;
  for (const ParamInfo& p : id.unidentifiable) {
    if (p.kind != ParamKind::kPoint) out.push_back(p.name);
  }
  return out;
}

// eps over a grid of offsets of one parameter (+-options.range, options.
// steps points), its valley refined by golden section inside the grid
// bracket; a flat curve keeps offset 0.
SensitivityCurve TraceCurve(const std::vector<Measurement>& ms,
                            const ParamInfo& p,
                            const SensitivityOptions& options,
                            ModelState* state) {
  const int half = options.steps / 2;
  SensitivityCurve c;
  c.param = p;
  c.unit = p.angle ? "deg" : "mm";
  const double x0 = ParamValue(*state, p);
  c.value = p.ToInterface(x0);
  const double unit = p.FromInterface(1.0);  // 1 mm or 1 deg, internal
  const double h = options.range / half;     // interface units
  for (int k = -half; k <= half; ++k) {
    c.offsets.push_back(k * h);
    c.eps_mm.push_back(EpsAt(state, ms, p, x0 + k * h * unit));
  }
  const auto [lo, hi] = std::minmax_element(c.eps_mm.begin(), c.eps_mm.end());
  c.flat = *hi - *lo < options.flat_tolerance_mm;
  int best = static_cast<int>(lo - c.eps_mm.begin());
  const double a = c.offsets[std::max(best - 1, 0)];
  const double b = c.offsets[std::min(best + 1, options.steps - 1)];
  c.valley_mm = *lo;
  c.valley_offset = c.offsets[best];
  if (c.flat) {
    c.valley_offset = 0.0;
    c.valley_mm = c.eps_mm[half];
    return c;
  }
  const GoldenSectionResult m = GoldenSectionMinimize(
      [&](double x) { return EpsAt(state, ms, p, x0 + x * unit); }, a, b, 40);
  if (m.f < c.valley_mm) {
    c.valley_mm = m.f;
    c.valley_offset = m.x;
  }
  return c;
}

// The verdict: valleys equal (within the tolerance) and below eta; the
// reasons when not.
void Judge(const SensitivityOptions& options, SensitivityResult* r) {
  r->valley_min_mm = r->valley_max_mm = r->curves.front().valley_mm;
  for (const SensitivityCurve& c : r->curves) {
    r->valley_min_mm = std::min(r->valley_min_mm, c.valley_mm);
    r->valley_max_mm = std::max(r->valley_max_mm, c.valley_mm);
  }
  r->valleys_equal =
      r->valley_max_mm - r->valley_min_mm <= r->valley_tolerance_mm;
  r->below_eta = r->valley_max_mm < options.eta_mm;
  r->verdict = r->valleys_equal && r->below_eta ? "optimal" : "not_optimal";
  for (const SensitivityCurve& c : r->curves) {
    if (c.improves) {
      std::ostringstream os;
      os << c.param.name << ": eps falls from " << r->eps_mm << " to "
         << c.valley_mm << " mm at " << (c.valley_offset >= 0 ? "+" : "")
         << c.valley_offset << " " << c.unit;
      r->reasons.push_back(os.str());
    }
  }
  if (!r->below_eta) {
    std::ostringstream os;
    os << "valleys up to " << r->valley_max_mm
       << " mm exceed eta = " << options.eta_mm << " mm";
    r->reasons.push_back(os.str());
  }
}

// What the criterion cannot see.
void AddNotes(SensitivityResult* r) {
  if (!r->flat.empty()) {
    r->notes.push_back(std::to_string(r->flat.size()) +
                       " flat curves (eps does not depend on them, so their "
                       "valleys equal eps trivially and say nothing about "
                       "their values): " +
                       Join(r->flat));
  }
  std::vector<std::string> combos;
  for (const std::string& name : r->unidentifiable) {
    if (std::find(r->flat.begin(), r->flat.end(), name) == r->flat.end()) {
      combos.push_back(name);
    }
  }
  if (!combos.empty()) {
    r->notes.push_back(
        std::to_string(combos.size()) +
        " parameters act on eps alone but only in combinations the data "
        "cannot separate (an error shared along the combination leaves every "
        "curve unchanged): " +
        Join(combos));
  }
  r->notes.push_back(
      "equal valleys certify only that no single-parameter change lowers "
      "eps; they do not certify the parameters, and eps at the fixed point "
      "is not the error elsewhere in the workspace");
}

}  // namespace

SensitivityResult AnalyzeSensitivity(const Robot& robot,
                                     const Observations& obs,
                                     const SensitivityOptions& options) {
  options.Check();
  ModelState state;
  state.chain = Chain::FromRobot(robot);
  std::vector<int> count;
  const std::vector<Measurement> ms = FixedPointRows(obs, &state, &count);
  std::vector<ParamInfo> params;
  if (options.params.empty()) {
    params = GeometryParams(state.chain);
  } else {
    for (const std::string& name : options.params) {
      params.push_back(FindParam(state, name));
    }
  }

  SensitivityResult r;
  const std::vector<double> d = PaperDistances(state, ms);
  r.epsilon = ComputeErrorStats(d);
  r.eps_mm = r.epsilon.mean_mm;
  r.valley_tolerance_mm =
      std::max(options.valley_tolerance_mm,
               options.valley_tolerance_fraction * r.eps_mm);
  r.unidentifiable = UnidentifiableAtCentroids(ms, count, params, &state);

  for (const ParamInfo& p : params) {
    SensitivityCurve c = TraceCurve(ms, p, options, &state);
    // A flat curve means eps, hence the data, cannot determine the
    // parameter, even where the Jacobian test (taken at noisy tips that do
    // not coincide exactly) still sees a sliver of it.
    const bool listed =
        std::find(r.unidentifiable.begin(), r.unidentifiable.end(), p.name) !=
        r.unidentifiable.end();
    if (c.flat && !listed) r.unidentifiable.push_back(p.name);
    c.identifiable = !listed && !c.flat;
    c.improves = c.valley_mm < r.eps_mm - r.valley_tolerance_mm;
    if (c.flat) r.flat.push_back(p.name);
    r.curves.push_back(c);
  }
  Judge(options, &r);
  AddNotes(&r);
  return r;
}

}  // namespace kincal
