#ifndef KINCAL_CAPTURE_CAPTURE_SESSION_H_
#define KINCAL_CAPTURE_CAPTURE_SESSION_H_

// Records one session (one image folder per camera, frames.csv,
// session.yaml; docs/CAPTURE.md) from 1..N cameras or 1..N recordings, the
// workflow behind `kincal capture`:
//
//   1. check every input before a camera or file is touched (camera names,
//      sources, joint log, robot file, an absent or empty --out);
//   2. with a robot link and no --stream, hand over to step and shoot
//      (capture/step_and_shoot.h);
//   3. otherwise open the cameras (and the robot's joint stream), record
//      frame sets (one image per camera, capture/frame_grabber.h) through
//      the asynchronous writers until a limit, the end of the recordings,
//      the robot's BYE or Ctrl-C;
//   4. merge the joint readings (a log by time, or the stream) into
//      frames.csv and finalize the session.

#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "capture/step_and_shoot.h"
#include "data/warnings.h"

namespace kincal::capture {

// One camera to record.
struct CaptureCamera {
  std::string name;  // as in rig.yaml: image folder, frames.csv columns
  std::string uri;   // source URI (capture/frame_source.h)
};

struct CaptureOptions {
  // 1..N cameras in rig order (the first is the reference); all cameras or
  // all recordings. `kincal capture --left/--right` is {left, right}.
  std::vector<CaptureCamera> cameras;
  std::string out;               // session folder: must not exist or be empty
  int64_t frames = 0;            // stop after N sets (0: no limit)
  double seconds = 0;            // stop after S seconds (0: no limit)
  double tolerance_ms = 10;      // live: largest time spread within a set
  int png_compression = 1;       // zlib level 0-9 (all lossless)
  int max_failures = 3;          // live: consecutive timeouts tolerated
  int queue_sets = 32;           // frame sets waiting for the writers
  int writers = 2;               // PNG writer threads
  std::string joints;            // controller joint log merged by time
  std::string robot;             // robot.yaml naming the joints
  double joints_offset = NAN;    // s, t_frame = t_log + offset; NaN: estimate
  double max_joint_speed = 1.0;  // deg/s | mm/s: faster frames get no reading
  std::string robot_listen;      // HOST:PORT of the robot link
  int shots = 5;                 // step and shoot: sets averaged per pose
  double robot_timeout = 600;    // s: connect, and between messages
  bool stream = false;           // with robot_listen: record continuously
  // Messages on stderr ("waiting for the robot", "recording until Ctrl-C")
  // and the progress line; off for --json.
  bool announce = true;
  const std::atomic<bool>* interrupted = nullptr;  // Ctrl-C
  // Called once the session is about to be recorded (after the robot's
  // HELLO in stream mode), e.g. to install the Ctrl-C handler that sets
  // `interrupted`; Ctrl-C before then ends the process.
  std::function<void()> before_recording;
};

// The joint readings merged into frames.csv.
struct CaptureJoints {
  bool from_stream = false;  // the robot's J lines, else the log file
  std::string log;           // the log file
  int64_t samples = 0;       // stream readings received
  double offset_s = 0;
  bool offset_estimated = false;
  double agreement = 0;  // estimated offset only
  int stops_matched = 0;
  int frames_with_reading = 0;
  int frames_too_fast = 0;
};

// A recorded camera.
struct CapturedCamera {
  std::string name;
  std::string uri;
  std::string description;  // FrameSource::Describe() after opening
  int64_t dropped = 0;      // frames in no set (no partner in time, or extra)
  std::string mosaic;       // FrameSource::mosaic(): raw pattern, or empty
};

struct CaptureResult {
  enum Outcome { kOk, kBadInput, kFailure };
  Outcome outcome = kOk;
  // kBadInput: the whole error text; kFailure: what follows "failure: ".
  std::string message;
  bool step_and_shoot = false;
  StepAndShootResult step;  // when step_and_shoot
  // Continuous recording (not step_and_shoot): a session was created and
  // the fields below describe it.
  bool recorded = false;
  int64_t frames = 0;
  double seconds = 0;
  uint64_t bytes = 0;
  std::vector<CapturedCamera> cameras;  // in rig order (step and shoot too)
  std::string pairing;
  int64_t dropped_sets = 0;  // the writers were slower than the cameras
  int max_queue_depth = 0;
  int64_t fast_sets = 0;         // written at PNG level 0 to catch up
  bool length_mismatch = false;  // recordings of different lengths
  int64_t transient_failures = 0;
  std::string stop_reason;
  bool complete = false;  // no camera, disk or robot failure
  bool has_joints = false;
  CaptureJoints joints;  // when has_joints
  // Inputs that look wrong (data/warnings.h); already on stderr.
  std::vector<Warning> warnings;
};

// Throws InputError for bad input found before anything is written. A
// failure, or bad input found after the session was created, is the
// result's outcome; a created session is always kept and finalized.
CaptureResult RunCaptureSession(const CaptureOptions& options);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_CAPTURE_SESSION_H_
