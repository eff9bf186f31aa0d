#include "calib/identifiability.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kincal {

std::vector<std::string> Identifiability::IdentifiableNames() const {
  std::vector<std::string> names;
  for (const auto& p : identifiable) names.push_back(p.name);
  return names;
}

int Identifiability::RobotParameterCount() const {
  int n = 0;
  for (const auto& p : identifiable) {
    n += p.kind != ParamKind::kFrame && p.kind != ParamKind::kPoint ? 1 : 0;
  }
  return n;
}

std::vector<std::string> Identifiability::UnidentifiableNames() const {
  std::vector<std::string> names;
  for (const auto& p : unidentifiable) names.push_back(p.name);
  return names;
}

Identifiability AnalyzeIdentifiability(
    const std::vector<Measurement>& measurements, const ModelState& state,
    const std::vector<ParamInfo>& candidates,
    const IdentifiabilityOptions& options,
    const std::vector<PointDistance>& distances) {
  return AnalyzeJacobianColumns(
      ResidualJacobian(measurements, state, candidates, distances), candidates,
      state.chain, options);
}

Identifiability AnalyzeJacobianColumns(const Eigen::MatrixXd& jac,
                                       const std::vector<ParamInfo>& candidates,
                                       const Chain& chain,
                                       const IdentifiabilityOptions& options) {
  Identifiability out;
  const int m = static_cast<int>(jac.rows());
  Eigen::MatrixXd basis(m, 0);  // orthonormal basis of accepted columns
  std::vector<int> accepted;
  std::vector<Eigen::VectorXd> unit_columns;
  for (int c = 0; c < static_cast<int>(candidates.size()); ++c) {
    const double norm = jac.col(c).norm();
    Eigen::VectorXd col = norm > 0 ? Eigen::VectorXd(jac.col(c) / norm)
                                   : Eigen::VectorXd(jac.col(c));
    unit_columns.push_back(col);
    Eigen::VectorXd rest = col;
    // Two passes of Gram-Schmidt for numerical orthogonality.
    for (int pass = 0; pass < 2 && basis.cols() > 0; ++pass) {
      rest -= basis * (basis.transpose() * rest);
    }
    const double sine = norm > 0 ? rest.norm() : 0.0;
    // Predicted sigma given the accepted parameters (internal units).
    const double sigma = options.noise_sigma_mm > 0 && sine > 0
                             ? options.noise_sigma_mm / (sine * norm)
                             : NAN;
    bool determined = sine > options.tolerance;
    if (determined && options.noise_sigma_mm > 0 &&
        candidates[c].kind == ParamKind::kRow) {
      const bool angle = candidates[c].angle;
      const double bound =
          angle ? chain.bound_angle_rad : chain.bound_length_mm;
      determined = sigma < options.max_sigma_fraction * bound;
    }
    if (determined) {
      out.conditional_sigma.push_back(candidates[c].angle ? sigma * 180 / M_PI
                                                          : sigma);
      basis.conservativeResize(m, basis.cols() + 1);
      basis.col(basis.cols() - 1) = rest / rest.norm();
      accepted.push_back(c);
      out.identifiable.push_back(candidates[c]);
      if (sine < options.weak_tolerance) out.weak.push_back(candidates[c].name);
      continue;
    }
    out.unidentifiable.push_back(candidates[c]);
    // The redundancy: express the column (physical units) by the accepted
    // ones, d(residual)/d(this) = sum_k coef_k d(residual)/d(accepted_k).
    std::string relation = candidates[c].name + " =";
    if (norm == 0 || accepted.empty()) {
      relation += " (no effect on any residual)";
    } else {
      Eigen::MatrixXd a(m, accepted.size());
      for (size_t k = 0; k < accepted.size(); ++k)
        a.col(k) = jac.col(accepted[k]);
      const Eigen::VectorXd coef =
          a.colPivHouseholderQr().solve(Eigen::VectorXd(jac.col(c)));
      std::vector<int> order(accepted.size());
      for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
      // Compare coefficients in interface units (deg for angles).
      auto shown = [&](int k) {
        double v = coef[k];
        const ParamInfo& pk = candidates[accepted[k]];
        if (pk.angle != candidates[c].angle) {
          v = candidates[c].angle ? v * M_PI / 180.0 : v * 180.0 / M_PI;
        }
        return v;
      };
      std::sort(order.begin(), order.end(), [&](int x, int y) {
        return std::abs(shown(x)) > std::abs(shown(y));
      });
      int terms = 0;
      for (int k : order) {
        const double v = shown(k);
        if (terms == 4 || std::abs(v) < 1e-3) break;
        char buf[96];
        std::snprintf(buf, sizeof(buf), " %+.3f %s", v,
                      candidates[accepted[k]].name.c_str());
        relation += buf;
        ++terms;
      }
      if (terms == 0) relation += " (no effect on any residual)";
    }
    out.relations.push_back(relation);
  }
  if (!accepted.empty()) {
    Eigen::MatrixXd a(m, accepted.size());
    for (size_t k = 0; k < accepted.size(); ++k)
      a.col(k) = unit_columns[accepted[k]];
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
    const Eigen::VectorXd s = svd.singularValues();
    for (int k = 0; k < s.size(); ++k) out.singular_values.push_back(s[k]);
    out.condition = s[s.size() - 1] > 0 ? s[0] / s[s.size() - 1] : INFINITY;
  }
  return out;
}

}  // namespace kincal
