#ifndef KINCAL_CAPTURE_JOINT_LOG_H_
#define KINCAL_CAPTURE_JOINT_LOG_H_

// Joint readings into a session by time (spec v2, "Joint log"): a robot
// controller's log `joints.csv` (`t` in seconds on the controller's clock,
// then one column per joint in the robot's units, rows in time order) is
// interpolated (linearly) at each frame's time.
//
// Clocks: t_frame = t_log + offset. The offset is given, or estimated from
// the data: when the robot stops, the images stop changing. The log's
// stop events (speed falling below `still_speed`) are matched with the
// session's (image motion falling below its threshold); the offset that
// puts the most image stops next to log stops is then refined on a 1 ms
// grid by the agreement of the two moving/still indicators frame by frame.
//
// A frame whose interpolated joint speed (largest |dq/dt| over the joints,
// deg/s or mm/s) exceeds `max_speed` gets no reading (NaN): its image and
// its reading would not show the same pose.

#include <optional>
#include <string>
#include <vector>

namespace kincal::capture {

struct JointLog {
  std::string source;
  std::vector<std::string> names;      // joint columns in file order
  std::vector<double> t;               // strictly increasing
  std::vector<std::vector<double>> q;  // per row, per name
  std::vector<int> lines;              // per row: line in the file (1-based)
};

// Strict reader: `t` column required; every other column a joint; when
// `expected` is given (the robot's joint names) the joint columns must be
// exactly those names (any order; unknown or missing -> InputError naming
// them). Rows: every cell a finite number; t strictly increasing (a clock
// going backwards is an error) and no step longer than max_gap_s (a clock
// jump or a hole in the log). Messages carry file:line:column.
JointLog ParseJointLog(const std::string& text, const std::string& label,
                       const std::vector<std::string>* expected,
                       double max_gap_s = 1.0);
JointLog ReadJointLog(const std::string& path,
                      const std::vector<std::string>* expected,
                      double max_gap_s = 1.0);

struct JointMergeOptions {
  std::optional<double> offset_s;  // t_frame = t_log + offset
  double max_speed = 1.0;          // deg/s | mm/s: faster -> no reading
  double still_speed = 0.2;        // deg/s | mm/s: slower = robot still
  // Frames outside the log get no reading instead of an error (a live
  // stream that ended early).
  bool uncovered_ok = false;
  // An estimated offset whose moving/still agreement is below this is
  // refused (InputError): two random indicators agree about half the time,
  // a log of this session's motion in nearly every frame.
  double min_agreement = 0.8;
};

struct JointMerge {
  double offset_s = 0;
  bool estimated = false;
  // Fraction of frames whose image moving/still state agrees with the
  // log's at the chosen offset (estimated offsets only; else NaN).
  double agreement = 0;
  int stops_matched = 0;
  // Per frame, per log joint (in `names` order): reading or NaN.
  std::vector<std::vector<double>> joints;
  std::vector<std::string> names;
  int with_reading = 0;
  int too_fast = 0;
};

// `frame_times` (s, the session's clock, increasing) and `image_motion`
// (one number per frame, larger = more change since the previous frame;
// needed only to estimate the offset). InputError when the offset cannot be
// estimated (no stops seen), the estimate's agreement is below
// options.min_agreement (the message gives the offset and the agreement) or
// the log does not cover every frame.
JointMerge MergeJointLog(const JointLog& log,
                         const std::vector<double>& frame_times,
                         const std::vector<double>& image_motion,
                         const JointMergeOptions& options);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_JOINT_LOG_H_
