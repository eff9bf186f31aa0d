#include "calib/evaluate.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "data/error.h"

namespace kincal {

Registration Register(const ModelState& start,
                      const std::vector<Measurement>& ms,
                      const std::vector<char>& excluded) {
  Registration out;
  out.state = start;
  std::vector<Measurement> used;
  for (size_t i = 0; i < ms.size(); ++i)
    if (!excluded[i]) used.push_back(ms[i]);
  InitializeFrameAndPoints(used, &out.state);
  // Measured rows alone: the frames from InitializeFrameAndPoints (Umeyama
  // per frame) already minimise the squared residuals, as the model's tips
  // do not depend on them. Fixed points (and their frames) need the fit.
  const bool only_measured = std::all_of(
      used.begin(), used.end(),
      [](const Measurement& m) { return m.kind == Measurement::kMeasured; });
  if (!only_measured) {
    FitOptions options;
    options.free = FrameParams();
    for (const ParamInfo& p : PointParams(out.state)) options.free.push_back(p);
    options.compute_covariance = false;
    Fit(used, options, &out.state);
  }
  std::vector<double> used_errors;
  for (size_t i = 0; i < ms.size(); ++i) {
    out.errors_mm.push_back(Residual(out.state, ms[i]).norm());
    if (!excluded[i]) used_errors.push_back(out.errors_mm.back());
  }
  out.stats = ComputeErrorStats(used_errors);
  return out;
}

namespace {

// One series registered on its own measurements: on all of them, and
// without its gross errors when it has any.
struct SeriesRun {
  Registration all;
  std::vector<char> excluded;  // per measurement; empty without gross errors
  bool has_robust = false;
  Registration robust;
};

SeriesRun RunSeries(const ModelState& start, const std::vector<Measurement>& ms,
                    double outlier_sigmas) {
  SeriesRun run;
  const std::vector<char> excluded = FindGrossErrors(start, ms, outlier_sigmas);
  run.all = Register(start, ms, std::vector<char>(ms.size(), 0));
  if (std::find(excluded.begin(), excluded.end(), 1) == excluded.end()) {
    return run;
  }
  run.has_robust = true;
  run.excluded = excluded;
  run.robust = Register(start, ms, excluded);
  return run;
}

// The measurements (indices into `ms`) of every series with usable rows, in
// the series' first-seen order.
std::vector<std::pair<std::string, std::vector<int>>> GroupBySeries(
    const Observations& obs, const std::vector<Measurement>& ms) {
  std::vector<std::pair<std::string, std::vector<int>>> groups;
  for (const std::string& name : obs.SeriesNames()) {
    std::vector<int> members;
    for (size_t i = 0; i < ms.size(); ++i) {
      if (obs.rows[ms[i].row].series == name) {
        members.push_back(static_cast<int>(i));
      }
    }
    if (!members.empty()) groups.emplace_back(name, members);
  }
  return groups;
}

// `states[s]` registered series s; the result is series 0's state with each
// fixed point taken from the first series that has rows at it.
ModelState MergeStates(const std::vector<ModelState>& states,
                       const std::vector<std::vector<Measurement>>& series_ms) {
  ModelState merged = states.at(0);
  for (size_t k = 0; k < merged.points_in_base.size(); ++k) {
    bool found = false;
    for (size_t s = 0; s < states.size() && !found; ++s) {
      for (const Measurement& m : series_ms[s]) {
        if (m.kind != Measurement::kFixedPoint ||
            m.point != static_cast<int>(k))
          continue;
        merged.points_in_base[k] = states[s].points_in_base[k];
        found = true;
        break;
      }
    }
  }
  return merged;
}

// RMS of the errors in [begin, end) of `errors_mm`.
double RangeRms(const std::vector<double>& errors_mm, size_t begin,
                size_t end) {
  std::vector<double> part(errors_mm.begin() + begin, errors_mm.begin() + end);
  return ComputeErrorStats(part).rms_mm;
}

// The split of `errors_mm` (errors against the frame of one end's block)
// with the fewest rows on the wrong side of `threshold_mm`: small before
// the split and large after it (`small_first`), or the reverse.
size_t BestSplit(const std::vector<double>& errors_mm, double threshold_mm,
                 bool small_first) {
  const size_t n = errors_mm.size();
  // wrong = rows before the split on the wrong side + rows after it.
  size_t wrong_after = 0;
  for (double e : errors_mm) {
    wrong_after += ((e > threshold_mm) == small_first) ? 0 : 1;
  }
  size_t best = 0, best_wrong = wrong_after, wrong_before = 0;
  for (size_t k = 0; k < n; ++k) {
    const bool large = errors_mm[k] > threshold_mm;
    wrong_before += (large == small_first) ? 1 : 0;
    wrong_after -= (large == small_first) ? 0 : 1;
    if (wrong_before + wrong_after < best_wrong) {
      best_wrong = wrong_before + wrong_after;
      best = k + 1;
    }
  }
  return best;
}

// Both blocks of `ms` split at `split`, each registered on its own frame.
bool TrySplit(const ModelState& start, const std::vector<Measurement>& ms,
              size_t split, FrameJump* jump) {
  constexpr size_t kMinRows = 6;
  if (split < kMinRows || ms.size() - split < kMinRows) return false;
  const std::vector<Measurement> before(ms.begin(), ms.begin() + split);
  const std::vector<Measurement> after(ms.begin() + split, ms.end());
  try {
    jump->before_rms_mm =
        Register(start, before, std::vector<char>(before.size(), 0))
            .stats.rms_mm;
    jump->after_rms_mm =
        Register(start, after, std::vector<char>(after.size(), 0)).stats.rms_mm;
  } catch (const InputError&) {
    return false;  // a block too small or flat to register
  }
  jump->first_row_after = ms[split].row;
  return true;
}

}  // namespace

FrameJump FindFrameJump(const Robot& robot, const Observations& obs,
                        const FrameJumpOptions& options) {
  FrameJump jump;
  ModelState start;
  start.chain = Chain::FromRobot(robot);
  std::vector<Measurement> ms;
  for (const Measurement& m : MakeMeasurements(start.chain, obs, &start)) {
    if (m.kind == Measurement::kMeasured) ms.push_back(m);
  }
  constexpr size_t kMinRows = 20;
  if (ms.size() < kMinRows) return jump;
  try {
    jump.one_frame_rms_mm =
        Register(start, ms, std::vector<char>(ms.size(), 0)).stats.rms_mm;
  } catch (const InputError&) {
    return jump;  // calibrate says what is wrong with the points
  }
  if (!(jump.one_frame_rms_mm > options.min_one_frame_rms_mm)) return jump;
  const size_t block = std::max<size_t>(6, ms.size() / 10);
  for (const bool from_start : {true, false}) {
    const std::vector<Measurement> end_block(
        from_start ? ms.begin() : ms.end() - block,
        from_start ? ms.begin() + block : ms.end());
    std::vector<double> errors;
    try {
      const ModelState frame =
          Register(start, end_block, std::vector<char>(block, 0)).state;
      for (const Measurement& m : ms)
        errors.push_back(Residual(frame, m).norm());
    } catch (const InputError&) {
      continue;
    }
    const double block_rms =
        from_start ? RangeRms(errors, 0, block)
                   : RangeRms(errors, ms.size() - block, ms.size());
    const double threshold = std::sqrt(block_rms * jump.one_frame_rms_mm);
    const size_t split = BestSplit(errors, threshold, from_start);
    if (!TrySplit(start, ms, split, &jump)) continue;
    if (std::max(jump.before_rms_mm, jump.after_rms_mm) <
        options.max_ratio * jump.one_frame_rms_mm) {
      jump.found = true;
      return jump;
    }
  }
  return jump;
}

void RequireNoFrameJump(const Robot& robot, const Observations& obs,
                        const std::string& command) {
  const std::vector<std::string> names = obs.SeriesNames();
  if (names.size() > 1) {  // each series on its own frame
    for (const std::string& name : names)
      RequireNoFrameJump(robot, Subset(obs, obs.SeriesRows(name)), command);
    return;
  }
  const FrameJump jump = FindFrameJump(robot, obs);
  if (!jump.found) return;
  const Observation& row = obs.rows.at(jump.first_row_after);
  std::ostringstream os;
  os.precision(3);
  os << std::fixed << "the rows before line " << row.line << " and from it on ("
     << "pose '" << row.pose << "') look like two measurement campaigns with "
     << "different measuring frames: one frame for all rows leaves "
     << jump.one_frame_rms_mm << " mm RMS, one frame per block "
     << jump.before_rms_mm << " and " << jump.after_rms_mm
     << " mm; add a `series` column labelling each campaign (`kincal "
     << command << "` fits one measuring frame per series)";
  throw InputError(obs.source, row.line, 0, os.str());
}

EvaluateResult Evaluate(const Robot& robot, const Observations& obs,
                        double outlier_sigmas) {
  EvaluateResult out;
  ModelState start;
  start.chain = Chain::FromRobot(robot);
  // Approach directions and torques use the model's own geometry.
  const std::vector<Measurement> ms =
      MakeMeasurements(start.chain, obs, &start);
  if (ms.empty()) {
    throw InputError(obs.source, 0, 0,
                     "no row has a measured tip (x, y, z) or a fixed_point "
                     "label: nothing to evaluate");
  }
  for (const Measurement& m : ms) out.rows.push_back(m.row);
  const auto groups = GroupBySeries(obs, ms);
  out.errors_mm.assign(ms.size(), 0.0);
  std::vector<double> robust_errors(ms.size(), 0.0);
  std::vector<char> excluded(ms.size(), 0);
  std::vector<ModelState> states, robust_states;
  std::vector<std::vector<Measurement>> series_ms;
  std::vector<SeriesRun> runs;
  for (const auto& [name, members] : groups) {
    std::vector<Measurement> sub;
    for (int i : members) sub.push_back(ms[i]);
    try {
      runs.push_back(RunSeries(start, sub, outlier_sigmas));
    } catch (const InputError& e) {
      if (groups.size() < 2) throw;
      throw InputError(std::string(e.what()) + " (series '" + name + "')");
    }
    const SeriesRun& run = runs.back();
    const Registration& kept = run.has_robust ? run.robust : run.all;
    SeriesEvaluation se;
    se.name = name;
    se.usable = members;
    se.stats = run.all.stats;
    se.state = run.all.state;
    se.has_robust = run.has_robust;
    se.robust_stats = kept.stats;
    out.series.push_back(se);
    for (size_t k = 0; k < members.size(); ++k) {
      out.errors_mm[members[k]] = run.all.errors_mm[k];
      robust_errors[members[k]] = kept.errors_mm[k];
      if (run.has_robust) excluded[members[k]] = run.excluded[k];
    }
    states.push_back(run.all.state);
    robust_states.push_back(kept.state);
    series_ms.push_back(sub);
  }
  // The spec's figures: every row registered (each on its series' frame).
  out.stats = ComputeErrorStats(out.errors_mm);
  out.state = MergeStates(states, series_ms);
  if (std::find(excluded.begin(), excluded.end(), 1) == excluded.end()) {
    return out;
  }
  out.has_robust = true;
  out.excluded = excluded;
  out.robust.errors_mm = robust_errors;
  std::vector<double> kept_errors;
  for (size_t i = 0; i < ms.size(); ++i) {
    if (!excluded[i]) kept_errors.push_back(robust_errors[i]);
  }
  out.robust.stats = ComputeErrorStats(kept_errors);
  out.robust.state = MergeStates(robust_states, series_ms);
  out.outlier_axis_sigma_mm = RobustAxisSigmaOfKeptMm(robust_errors, excluded);
  for (size_t s = 0; s < runs.size(); ++s) {
    if (!runs[s].has_robust) continue;
    const SeriesRun& run = runs[s];
    const double sigma =
        RobustAxisSigmaOfKeptMm(run.robust.errors_mm, run.excluded);
    for (size_t k = 0; k < series_ms[s].size(); ++k) {
      if (!run.excluded[k]) continue;
      const Measurement& m = series_ms[s][k];
      RowOutlier o =
          DescribeOutlier(run.robust.state, m, obs.rows[m.row].pose,
                          run.robust.errors_mm[k], sigma, outlier_sigmas);
      o.excluded = true;
      out.outliers.push_back(o);
    }
  }
  return out;
}

}  // namespace kincal
