#include "calib/fit_record.h"

#include <algorithm>
#include <cmath>

#include "calib/chain.h"

namespace kincal {

TravelGap LargestGap(const Observations& obs, int joint,
                     const std::vector<int>& rows) {
  std::vector<double> q;
  if (rows.empty()) {
    for (const Observation& o : obs.rows) q.push_back(o.q[joint]);
  } else {
    for (int i : rows) q.push_back(obs.rows[i].q[joint]);
  }
  std::sort(q.begin(), q.end());
  TravelGap g;
  if (q.empty()) return g;
  g.lo = q.front();
  g.hi = q.back();
  g.from = g.to = g.lo;
  for (size_t i = 1; i < q.size(); ++i) {
    if (q[i] - q[i - 1] > g.to - g.from) {
      g.from = q[i - 1];
      g.to = q[i];
    }
  }
  return g;
}

bool IsWideGap(const TravelGap& g, double fraction, double min_gap) {
  const double gap = g.to - g.from, travel = g.hi - g.lo;
  return travel > 0 && gap > fraction * travel && gap > min_gap;
}

FitRecord MakeFitRecord(const FitRecordInput& input) {
  FitRecord rec;
  const Observations& obs = *input.obs;
  std::vector<int> rows = input.rows;
  if (rows.empty()) {
    for (size_t i = 0; i < obs.rows.size(); ++i) {
      rows.push_back(static_cast<int>(i));
    }
  }
  rec.poses = static_cast<int>(rows.size());
  const size_t n = obs.joint_names.size();
  rec.joint_range.assign(n, {std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()});
  for (int i : rows) {
    const Observation& o = obs.rows[i];
    for (size_t j = 0; j < n; ++j) {
      rec.joint_range[j][0] = std::min(rec.joint_range[j][0], o.q[j]);
      rec.joint_range[j][1] = std::max(rec.joint_range[j][1], o.q[j]);
    }
    if (o.HasTemp()) {
      rec.temp_lo_c = rec.temp_lo_c == rec.temp_lo_c
                          ? std::min(rec.temp_lo_c, o.temp_c)
                          : o.temp_c;
      rec.temp_hi_c = rec.temp_hi_c == rec.temp_hi_c
                          ? std::max(rec.temp_hi_c, o.temp_c)
                          : o.temp_c;
    }
  }
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  rec.joint_gap.assign(n, {kNaN, kNaN});
  for (size_t j = 0; j < n; ++j) {
    const TravelGap g = LargestGap(obs, static_cast<int>(j), rows);
    if (IsWideGap(g)) rec.joint_gap[j] = {g.from, g.to};
  }
  rec.thermal_input = ThermalUsesTemperature(obs) ? "temp_c" : "hours";
  if (input.state != nullptr) {
    rec.has_frame = true;
    const auto& f = input.state->meas_from_base;
    for (int k = 0; k < 3; ++k) {
      rec.frame[k] = f[k] * 180.0 / M_PI;
      rec.frame[k + 3] = f[k + 3];
    }
    const ModelState& s = *input.state;
    if (s.NumFrames() > 1 &&
        static_cast<int>(s.frame_series.size()) == s.NumFrames()) {
      for (int i = 0; i < s.NumFrames(); ++i) {
        const double* b = s.FrameBlock(i);
        std::array<double, 6> frame{};
        for (int k = 0; k < 3; ++k) {
          frame[k] = b[k] * 180.0 / M_PI;
          frame[k + 3] = b[k + 3];
        }
        rec.series_frames.emplace_back(s.frame_series[i], frame);
      }
    }
  }
  rec.heldout_rms_mm = input.heldout_rms_mm;
  rec.systematic_rms_mm = input.systematic_rms_mm;
  const FitSummary* fit = input.fit;
  if (fit == nullptr ||
      fit->covariance.rows() != static_cast<int>(fit->params.size())) {
    return rec;
  }
  std::vector<int> keep;
  for (size_t k = 0; k < fit->params.size(); ++k) {
    const ParamInfo& q = fit->params[k];
    // A periodic transmission's coefficients weight the diagnosis' basis of
    // the readings; the file keeps the function's Fourier coefficients
    // (calib/chain.h FourierBasis), so their covariance has no name there.
    const bool periodic_coefficient =
        q.kind == ParamKind::kJointError && q.index >= kTransmission0 &&
        input.state != nullptr &&
        input.state->chain.rows[q.block].periodic();
    if (q.kind != ParamKind::kPoint && !periodic_coefficient) {
      keep.push_back(static_cast<int>(k));
    }
  }
  const int p = static_cast<int>(keep.size());
  rec.covariance.resize(p, p);
  for (int a = 0; a < p; ++a) {
    const ParamInfo& pa = fit->params[keep[a]];
    rec.covariance_params.push_back(pa.name);
    for (int b = 0; b < p; ++b) {
      const ParamInfo& pb = fit->params[keep[b]];
      // Internal -> interface: ToInterface is linear (rad -> deg).
      rec.covariance(a, b) = fit->covariance(keep[a], keep[b]) *
                             pa.ToInterface(1.0) * pb.ToInterface(1.0);
    }
  }
  if (!rec.covariance.allFinite()) {
    rec.covariance_params.clear();
    rec.covariance.resize(0, 0);
  }
  return rec;
}

Robot WithFitRecord(const Robot& calibrated, const Robot& nominal,
                    const FitRecordInput& input) {
  Robot out = calibrated;
  out.SetNominal(nominal);
  out.fitted_on = MakeFitRecord(input);
  return out;
}

}  // namespace kincal
