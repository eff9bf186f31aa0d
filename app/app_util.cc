#include "app/app_util.h"

#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "data/error.h"

namespace kincal::app {

void MakeDirs(const std::string& dir) {
  std::string path;
  for (size_t i = 0; i <= dir.size(); ++i) {
    if (i == dir.size() || dir[i] == '/') {
      if (!path.empty() && ::mkdir(path.c_str(), 0755) != 0 &&
          errno != EEXIST) {
        throw InputError(
            path, 0, 0,
            std::string("cannot create folder: ") + std::strerror(errno));
      }
    }
    if (i < dir.size()) path += dir[i];
  }
}

nlohmann::json Number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json StatsJson(const ErrorStats& s) {
  return {{"n", s.n},
          {"rms_mm", Number(s.rms_mm)},
          {"mean_mm", Number(s.mean_mm)},
          {"max_mm", Number(s.max_mm)},
          {"std_mm", Number(s.std_mm)}};
}

std::string ParamUnit(const ParamInfo& p) {
  if (p.kind == ParamKind::kJointError && p.index == kGain) return "1";
  if (p.kind == ParamKind::kJointError && p.index == kCompliance) {
    return p.angle ? "deg/mm" : "mm/mm";
  }
  if (p.kind == ParamKind::kDrift) return "mm/h";
  return p.angle ? "deg" : "mm";
}

nlohmann::json ParametersJson(const FitSummary& fit,
                              const ModelState& nominal) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t i = 0; i < fit.params.size(); ++i) {
    const ParamInfo& p = fit.params[i];
    nlohmann::json j = {{"name", p.name},
                        {"value", Number(fit.values[i])},
                        {"sigma", Number(fit.sigmas[i])},
                        {"unit", ParamUnit(p)}};
    if (p.kind == ParamKind::kRow) {
      j["nominal"] = Number(p.ToInterface(ParamValue(nominal, p)));
    }
    out.push_back(j);
  }
  return out;
}

}  // namespace kincal::app
