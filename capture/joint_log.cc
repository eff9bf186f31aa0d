#include "capture/joint_log.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"

namespace kincal::capture {
namespace {

std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

// Index i with t[i] <= x < t[i+1] (x within [t.front(), t.back()]).
size_t Segment(const std::vector<double>& t, double x) {
  auto it = std::upper_bound(t.begin(), t.end(), x);
  size_t i = it == t.begin() ? 0 : static_cast<size_t>(it - t.begin()) - 1;
  return std::min(i, t.size() - 2);
}

// Largest |dq/dt| over the joints on each log segment.
std::vector<double> SegmentSpeeds(const JointLog& log) {
  std::vector<double> speed(log.t.size() - 1, 0.0);
  for (size_t i = 0; i + 1 < log.t.size(); ++i) {
    const double dt = log.t[i + 1] - log.t[i];
    for (size_t j = 0; j < log.names.size(); ++j) {
      speed[i] =
          std::max(speed[i], std::abs(log.q[i + 1][j] - log.q[i][j]) / dt);
    }
  }
  return speed;
}

double SpeedAt(const JointLog& log, const std::vector<double>& speeds,
               double x) {
  // The faster of the two segments around a sample, so a frame at a
  // sample between a still and a moving segment counts as moving.
  const size_t i = Segment(log.t, x);
  double s = speeds[i];
  if (x - log.t[i] < 1e-9 && i > 0) s = std::max(s, speeds[i - 1]);
  return s;
}

// Times where the moving indicator turns still.
std::vector<double> StopEvents(const std::vector<double>& times,
                               const std::vector<char>& moving) {
  std::vector<double> events;
  for (size_t k = 1; k < times.size(); ++k) {
    if (moving[k - 1] && !moving[k]) events.push_back(times[k]);
  }
  return events;
}

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * (v.size() - 1))];
}

}  // namespace

JointLog ParseJointLog(const std::string& text, const std::string& label,
                       const std::vector<std::string>* expected,
                       double max_gap_s) {
  const std::vector<CsvLine> lines = TokenizeCsv(text, label);
  if (lines.empty()) throw InputError(label, 1, 1, "empty joint log");
  JointLog log;
  log.source = label;
  const CsvLine& header = lines[0];
  int t_col = -1;
  std::set<std::string> seen;
  std::vector<int> joint_cols;
  for (size_t c = 0; c < header.fields.size(); ++c) {
    const CsvField& f = header.fields[c];
    if (!seen.insert(f.text).second) {
      throw InputError(label, header.line, f.column,
                       "column '" + f.text + "' appears twice");
    }
    if (f.text == "t") {
      t_col = static_cast<int>(c);
      continue;
    }
    if (expected != nullptr && std::find(expected->begin(), expected->end(),
                                         f.text) == expected->end()) {
      std::string names;
      for (const std::string& n : *expected) names += " " + n;
      throw InputError(label, header.line, f.column,
                       "unknown joint '" + f.text +
                           "' (the robot's joints are:" + names + ")");
    }
    log.names.push_back(f.text);
    joint_cols.push_back(static_cast<int>(c));
  }
  if (t_col < 0) {
    throw InputError(label, header.line, 1, "expected a 't' column (seconds)");
  }
  if (log.names.empty()) {
    throw InputError(label, header.line, 1, "expected joint columns after t");
  }
  if (expected != nullptr) {
    for (const std::string& n : *expected) {
      if (!seen.count(n)) {
        throw InputError(label, header.line, header.end_column,
                         "missing the column of joint '" + n + "'");
      }
    }
  }
  for (size_t r = 1; r < lines.size(); ++r) {
    const CsvLine& line = lines[r];
    if (line.fields.size() != header.fields.size()) {
      throw InputError(label, line.line, line.end_column,
                       "expected " + std::to_string(header.fields.size()) +
                           " cells, found " +
                           std::to_string(line.fields.size()));
    }
    double t = 0;
    const CsvField& tf = line.fields[t_col];
    if (!ParseFiniteDouble(tf.text, &t)) {
      throw InputError(label, line.line, tf.column,
                       "expected a time in seconds, got '" + tf.text + "'");
    }
    if (!log.t.empty()) {
      const double dt = t - log.t.back();
      if (dt <= 0) {
        throw InputError(label, line.line, tf.column,
                         "time " + Num(t) + " s does not increase (previous " +
                             Num(log.t.back()) +
                             " s): the controller clock went backwards or "
                             "rows are out of order");
      }
      if (dt > max_gap_s) {
        throw InputError(label, line.line, tf.column,
                         "time jumps by " + Num(dt) + " s (from " +
                             Num(log.t.back()) + " to " + Num(t) +
                             "): a clock jump or a hole in the log (at most " +
                             Num(max_gap_s) + " s between rows)");
      }
    }
    std::vector<double> q;
    for (int c : joint_cols) {
      double v = 0;
      const CsvField& f = line.fields[c];
      if (!ParseFiniteDouble(f.text, &v)) {
        throw InputError(label, line.line, f.column,
                         "expected a number for joint '" +
                             header.fields[c].text + "', got '" + f.text + "'");
      }
      q.push_back(v);
    }
    log.t.push_back(t);
    log.q.push_back(q);
    log.lines.push_back(line.line);
  }
  if (log.t.size() < 2) {
    throw InputError(label, lines.back().line, 1,
                     "a joint log needs at least two rows");
  }
  return log;
}

JointLog ReadJointLog(const std::string& path,
                      const std::vector<std::string>* expected,
                      double max_gap_s) {
  return ParseJointLog(ReadFile(path), path, expected, max_gap_s);
}

namespace {

// The robot's stops as seen in the images and in the log, for the offset.
struct Stops {
  std::vector<double> img_times;  // image motion times (half a frame early)
  std::vector<char> img_moving;   // per frame: the image moves
  std::vector<double> img_stops, log_stops;
  double period = 0;  // mean frame period, s
};

Stops FindStops(const JointLog& log, const std::vector<double>& speeds,
                const std::vector<double>& frame_times,
                const std::vector<double>& image_motion,
                const JointMergeOptions& options) {
  Stops stops;
  const double first = frame_times.front(), last = frame_times.back();
  // Image moving/still: between the still level and the moving level.
  const double p10 = Percentile(image_motion, 0.1);
  const double p90 = Percentile(image_motion, 0.9);
  const double threshold = p10 + 0.3 * (p90 - p10);
  stops.img_moving.resize(frame_times.size());
  for (size_t k = 0; k < frame_times.size(); ++k) {
    stops.img_moving[k] = image_motion[k] > threshold;
  }
  std::vector<char> log_moving(log.t.size());
  for (size_t i = 0; i < log.t.size(); ++i) {
    log_moving[i] = SpeedAt(log, speeds, log.t[i]) > options.still_speed;
  }
  // Image motion k is the change from frame k-1 to frame k: it shows the
  // robot's motion half a frame period before frame k.
  stops.period = (last - first) / std::max<size_t>(1, frame_times.size() - 1);
  stops.img_times = frame_times;
  for (double& t : stops.img_times) t -= 0.5 * stops.period;
  stops.img_stops = StopEvents(stops.img_times, stops.img_moving);
  stops.log_stops = StopEvents(log.t, log_moving);
  if (stops.img_stops.empty() || stops.log_stops.empty() || p90 <= p10) {
    throw InputError(
        log.source, 0, 0,
        "cannot estimate the clock offset: the " +
            std::string(stops.img_stops.empty() || p90 <= p10 ? "images"
                                                              : "joint log") +
            " show no stop of the robot; give --joints-offset");
  }
  return stops;
}

// The offset in [lo, hi] that best matches image stops to log stops;
// InputError when none matches or a distinct one fits as well.
double MatchStops(const JointLog& log, const Stops& stops, double lo,
                  double hi) {
  const std::vector<double>& img_stops = stops.img_stops;
  const std::vector<double>& log_stops = stops.log_stops;
  const double period = stops.period;
  auto event_cost = [&](double offset) {
    double cost = 0;
    for (double e : img_stops) {
      const double x = e - offset;
      auto it = std::lower_bound(log_stops.begin(), log_stops.end(), x);
      double d = 1e9;
      if (it != log_stops.end()) d = std::min(d, *it - x);
      if (it != log_stops.begin()) d = std::min(d, x - *(it - 1));
      cost += std::min(d, 5 * period);
    }
    return cost;
  };
  double best = 0, best_cost = std::numeric_limits<double>::infinity();
  for (double ei : img_stops) {
    for (double el : log_stops) {
      const double offset = ei - el;
      if (offset < lo || offset > hi) continue;
      const double c = event_cost(offset);
      if (c < best_cost) {
        best_cost = c;
        best = offset;
      }
    }
  }
  // A second, distinct offset (more than a second away) that fits about
  // as well means the stops repeat periodically: refuse to guess.
  double second_cost = std::numeric_limits<double>::infinity();
  for (double ei : img_stops) {
    for (double el : log_stops) {
      const double offset = ei - el;
      if (offset < lo || offset > hi || std::abs(offset - best) < 1.0) {
        continue;
      }
      second_cost = std::min(second_cost, event_cost(offset));
    }
  }
  if (std::isfinite(best_cost) &&
      second_cost <= 1.2 * best_cost + 0.5 * period) {
    throw InputError(log.source, 0, 0,
                     "the clock offset is ambiguous: offsets " + Num(best) +
                         " s and "
                         "others fit the robot's stops equally well (a "
                         "periodic program?); "
                         "give --joints-offset or vary the dwell times");
  }
  if (!std::isfinite(best_cost)) {
    throw InputError(log.source, 0, 0,
                     "cannot estimate the clock offset: no stop of the "
                     "robot in the images matches one in the joint log "
                     "within its coverage; give --joints-offset");
  }
  return best;
}

// Estimates merge->offset_s from when the robot stops in the images and in
// the log, then refines it by the agreement of the moving indicators.
void EstimateOffset(const JointLog& log, const std::vector<double>& speeds,
                    const std::vector<double>& frame_times,
                    const std::vector<double>& image_motion, double lo,
                    double hi, const JointMergeOptions& options,
                    JointMerge* merge) {
  const double first = frame_times.front(), last = frame_times.back();
  if (lo > hi) {
    throw InputError(log.source, 0, 0,
                     "the joint log spans " +
                         Num(log.t.back() - log.t.front()) +
                         " s but the session " + Num(last - first) +
                         " s: it cannot cover the session");
  }
  if (image_motion.size() != frame_times.size()) {
    throw InputError(
        "cannot estimate the joint log's clock offset without "
        "image motion: give --joints-offset");
  }
  const Stops stops =
      FindStops(log, speeds, frame_times, image_motion, options);
  const double period = stops.period;
  double best = MatchStops(log, stops, lo, hi);
  // Refine: agreement of the moving indicators, 1 ms grid, +-2 periods;
  // the middle of the best plateau.
  auto agreement = [&](double offset) {
    int agree = 0;
    for (size_t k = 0; k < frame_times.size(); ++k) {
      const double x = std::max(stops.img_times[k] - offset, log.t.front());
      const bool m = SpeedAt(log, speeds, x) > options.still_speed;
      agree += m == static_cast<bool>(stops.img_moving[k]);
    }
    return static_cast<double>(agree) / frame_times.size();
  };
  double best_agree = -1;
  std::vector<double> plateau;
  for (double d = -2 * period; d <= 2 * period + 1e-12; d += 0.001) {
    const double offset = best + d;
    if (offset < lo || offset > hi) continue;
    const double a = agreement(offset);
    if (a > best_agree + 1e-12) {
      best_agree = a;
      plateau = {offset};
    } else if (a > best_agree - 1e-12) {
      plateau.push_back(offset);
    }
  }
  if (!plateau.empty()) best = 0.5 * (plateau.front() + plateau.back());
  merge->offset_s = best;
  merge->estimated = true;
  merge->agreement = best_agree;
  int matched = 0;
  for (double e : stops.img_stops) {
    for (double l : stops.log_stops) matched += std::abs(e - best - l) < period;
  }
  merge->stops_matched = matched;
}

// Per frame, the log's reading interpolated at the frame's time on the log
// clock; NaN while a joint moves faster than max_speed (or, uncovered_ok,
// outside the log).
void InterpolateReadings(const JointLog& log, const std::vector<double>& speeds,
                         const std::vector<double>& frame_times,
                         const JointMergeOptions& options, JointMerge* merge) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double tf : frame_times) {
    const double x = tf - merge->offset_s;
    std::vector<double> q(log.names.size(), nan);
    if (x < log.t.front() || x > log.t.back()) {  // uncovered_ok only
      merge->joints.push_back(q);
      continue;
    }
    const size_t i = Segment(log.t, x);
    const double w = (x - log.t[i]) / (log.t[i + 1] - log.t[i]);
    if (SpeedAt(log, speeds, x) > options.max_speed) {
      ++merge->too_fast;
    } else {
      for (size_t j = 0; j < q.size(); ++j) {
        q[j] = (1 - w) * log.q[i][j] + w * log.q[i + 1][j];
      }
      ++merge->with_reading;
    }
    merge->joints.push_back(q);
  }
}

// An estimated offset near chance agreement matches no motion of this
// session: refused, with what to do.
void RequireAgreement(const JointLog& log, const JointMerge& merge,
                      double min_agreement) {
  if (merge.agreement >= min_agreement) return;
  char percent[32];
  std::snprintf(percent, sizeof percent, "%.0f%%", 100.0 * merge.agreement);
  throw InputError(
      log.source, 0, 0,
      "the estimated clock offset " + Num(merge.offset_s) +
          " s agrees with the images in only " + percent +
          " of the frames (two unrelated recordings agree about half the "
          "time; below " +
          Num(100.0 * min_agreement) +
          "% is refused): the log may be of another session. Give "
          "--joints-offset if you know the offset, or record a motion both "
          "the cameras and the log see (moves with stops between them)");
}

}  // namespace

JointMerge MergeJointLog(const JointLog& log,
                         const std::vector<double>& frame_times,
                         const std::vector<double>& image_motion,
                         const JointMergeOptions& options) {
  JointMerge merge;
  merge.names = log.names;
  if (frame_times.empty()) return merge;
  const std::vector<double> speeds = SegmentSpeeds(log);
  const double first = frame_times.front(), last = frame_times.back();
  // Offsets for which the log covers every frame.
  const double lo = last - log.t.back(), hi = first - log.t.front();
  if (options.offset_s) {
    merge.offset_s = *options.offset_s;
    merge.agreement = std::numeric_limits<double>::quiet_NaN();
  } else {
    EstimateOffset(log, speeds, frame_times, image_motion, lo, hi, options,
                   &merge);
    RequireAgreement(log, merge, options.min_agreement);
  }
  // Coverage with the chosen offset.
  if (!options.uncovered_ok && (first - merge.offset_s < log.t.front() - 1e-9 ||
                                last - merge.offset_s > log.t.back() + 1e-9)) {
    throw InputError(log.source, 0, 0,
                     "the joint log does not cover the session: it spans " +
                         Num(log.t.front() + merge.offset_s) + " .. " +
                         Num(log.t.back() + merge.offset_s) +
                         " s on the session clock (offset " +
                         Num(merge.offset_s) + " s), the frames " + Num(first) +
                         " .. " + Num(last) + " s");
  }
  InterpolateReadings(log, speeds, frame_times, options, &merge);
  return merge;
}

}  // namespace kincal::capture
