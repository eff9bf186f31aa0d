#include "calib/fit_record.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "calib/chain.h"
#include "data/error.h"

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
  const std::vector<ParamInfo>* params =
      input.fit != nullptr ? &input.fit->params : input.params;
  const Eigen::MatrixXd* cov =
      input.fit != nullptr ? &input.fit->covariance : input.covariance;
  if (params == nullptr || cov == nullptr ||
      cov->rows() != static_cast<int>(params->size()) ||
      cov->cols() != cov->rows()) {
    return rec;
  }
  std::vector<int> keep;
  for (size_t k = 0; k < params->size(); ++k) {
    if ((*params)[k].kind != ParamKind::kPoint) {
      keep.push_back(static_cast<int>(k));
    }
  }
  if (input.state != nullptr) {
    // Only the rows whose fitted coefficients the covariance names.
    for (auto& jb : PeriodicBases(input.state->chain)) {
      const bool named = std::any_of(keep.begin(), keep.end(), [&](int k) {
        const ParamInfo& q = (*params)[k];
        return q.kind == ParamKind::kJointError && q.index >= kTransmission0 &&
               input.state->chain.rows[q.block].name == jb.first;
      });
      if (named) rec.periodic_bases.push_back(std::move(jb));
    }
  }
  const int p = static_cast<int>(keep.size());
  rec.covariance.resize(p, p);
  for (int a = 0; a < p; ++a) {
    const ParamInfo& pa = (*params)[keep[a]];
    rec.covariance_params.push_back(pa.name);
    for (int b = 0; b < p; ++b) {
      const ParamInfo& pb = (*params)[keep[b]];
      // Internal -> interface: ToInterface is linear (rad -> deg).
      rec.covariance(a, b) =
          (*cov)(keep[a], keep[b]) * pa.ToInterface(1.0) * pb.ToInterface(1.0);
    }
  }
  if (!rec.covariance.allFinite()) {
    rec.covariance_params.clear();
    rec.covariance.resize(0, 0);
  }
  return rec;
}

std::vector<std::pair<std::string, Eigen::MatrixXd>> PeriodicBases(
    const Chain& chain) {
  static_assert(kFourierTerms == kPeriodicTerms,
                "robot file and chain agree on the Fourier terms");
  std::vector<std::pair<std::string, Eigen::MatrixXd>> out;
  for (int j = 0; j < chain.num_joints(); ++j) {
    const ChainRow& row = chain.rows[j];
    // A row keeps a basis only while its transmission is in the model.
    if (!row.periodic() ||
        std::all_of(chain.joint_errors[j].begin() + kTransmission0,
                    chain.joint_errors[j].end(),
                    [](double c) { return c == 0.0; })) {
      continue;
    }
    const Eigen::Map<const Eigen::MatrixXd> b(
        row.periodic_basis.data(), kPeriodicTerms, kMaxTransmissionTerms);
    int m = kMaxTransmissionTerms;
    while (m > 0 && b.col(m - 1).isZero(0.0)) --m;
    if (m > 0) out.emplace_back(row.name, b.leftCols(m));
  }
  return out;
}

void ApplyPeriodicBases(const FitRecord& rec, Chain* chain) {
  for (const auto& [name, basis] : rec.periodic_bases) {
    int j = 0;
    while (j < chain->num_joints() && chain->rows[j].name != name) ++j;
    if (j == chain->num_joints() || !chain->rows[j].periodic() ||
        basis.rows() != kPeriodicTerms ||
        basis.cols() > kMaxTransmissionTerms) {
      throw InputError("covariance.periodic_basis." + name +
                       ": names no periodic transmission of the robot (" +
                       std::to_string(basis.rows()) + " x " +
                       std::to_string(basis.cols()) + ")");
    }
    ChainRow& row = chain->rows[j];
    const std::vector<double> f =
        PeriodicCoefficients(row, chain->joint_errors[j]);
    const Eigen::Map<const Eigen::VectorXd> fourier(f.data(), kPeriodicTerms);
    const Eigen::VectorXd c = basis.colPivHouseholderQr().solve(fourier);
    // The file prints 17 significant digits: B c reproduces F to rounding.
    if ((basis * c - fourier).norm() > 1e-6 * (1e-12 + fourier.norm())) {
      throw InputError("covariance.periodic_basis." + name +
                       ": does not reproduce the joint's Fourier "
                       "coefficients (was the file edited by hand? remove "
                       "covariance: or recalibrate)");
    }
    row.periodic_basis.assign(kPeriodicTerms * kMaxTransmissionTerms, 0.0);
    std::copy(basis.data(), basis.data() + basis.size(),
              row.periodic_basis.begin());
    for (int k = 0; k < kMaxTransmissionTerms; ++k) {
      chain->joint_errors[j][kTransmission0 + k] = k < c.size() ? c[k] : 0.0;
    }
  }
}

Robot WithFitRecord(const Robot& calibrated, const Robot& nominal,
                    const FitRecordInput& input) {
  Robot out = calibrated;
  out.SetNominal(nominal);
  out.fitted_on = MakeFitRecord(input);
  return out;
}

}  // namespace kincal
