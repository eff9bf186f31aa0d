#ifndef KINCAL_CAPTURE_STEP_AND_SHOOT_H_
#define KINCAL_CAPTURE_STEP_AND_SHOOT_H_

// Step and shoot with a live robot link (capture/robot_link.h; protocol and
// robot programs in docs/LAB.md): wait for the robot, check its HELLO
// against the robot's joint names (nothing is written before it passes),
// create the session, and at every SETTLED grab `shots` frame sets (one
// image per camera) taken after the message arrived (live sources; replay:
// the next sets), average them, record one set with the readings and answer
// DONE. J readings go to
// SESSION/joints.csv, one observations.csv row per recorded pose.

#include <atomic>
#include <string>
#include <vector>

#include "capture/frame_grabber.h"
#include "capture/recorder.h"

namespace kincal::capture {

struct StepAndShootOptions {
  std::string listen;                    // HOST:PORT
  std::vector<std::string> joint_names;  // robot.yaml order
  std::string robot_file;                // for messages
  int shots = 5;
  double timeout_s = 600;  // connect, and between messages
  std::string out;         // session folder
  SessionInfo info;        // sources; joints and mode are filled in
  SessionRecorder::Options recorder;
  const std::atomic<bool>* interrupted = nullptr;  // Ctrl-C
  bool announce = true;  // "waiting for the robot on port N" on stderr
};

struct StepAndShootResult {
  enum Outcome { kOk, kBadInput, kFailure };
  Outcome outcome = kOk;
  std::string message;  // what went wrong (kBadInput, kFailure)
  bool session_created = false;
  int64_t frames = 0;
  long poses = 0;
  std::string robot_name;
  bool joint_stream = false;
  std::string stop_reason;
  bool complete = false;
  double seconds = 0;
};

// The mean of the sets per camera (8-bit, rounded) with their mean
// timestamps; the sets hold the same cameras.
FrameSet AverageSets(const std::vector<FrameSet>& sets);

// `grabber` must be open. Never throws for robot or camera faults: they are
// the result's outcome, with the session kept when it was created.
StepAndShootResult RunStepAndShoot(FrameGrabber* grabber, bool live,
                                   const StepAndShootOptions& options);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_STEP_AND_SHOOT_H_
