#ifndef KINCAL_SYNTH_RECORDED_SESSION_H_
#define KINCAL_SYNTH_RECORDED_SESSION_H_

// Renders a recorded session in the spec's layout (../shared/spec/formats.md
// v3, "Recorded session with N cameras"; data/session.h reads it back), for
// a rig of 1..N cameras:
//
//   DIR/<camera>/000000.png ...   one folder per camera of the rig, named as
//                                 in rig.yaml; 8-bit gray, lossless
//   DIR/frames.csv    frame,t_<camera>...,seq_<camera>...,<joints>
//                     (frame,t_left,t_right,seq_left,seq_right,... for a
//                     left/right rig)
//   DIR/session.yaml  kincal_session: 1, status: complete, ...
//   DIR/truth.csv     frame, rig_from_tool (R row-major, t mm), tip in rig
//   DIR/corners.csv   frame, camera (index in the rig), tag, corner, u, v,
//                     visible (px)
//
// so `kincal track --session DIR` and `kincal bundle --session DIR` read it.

#include <cstdint>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "synth/render.h"
#include "vision/target.h"

namespace kincal {

struct RecordedSessionInput {
  std::vector<Rigid3> rig_from_tool;        // one per frame
  std::vector<std::string> joint_names;     // frames.csv joint columns
  std::vector<std::vector<double>> joints;  // per frame; empty = no reading
  std::vector<double> t_s;                  // per frame (empty: 0.1 s steps)
};

// Writes the session into `dir` (created; must not hold a session yet).
// Returns the number of frames. InputError for bad options, a camera name
// that cannot name a folder (data/session.h), a folder that is not writable
// or already has frames.csv.
int RenderRecordedSession(const Rig& rig, const Target& target,
                          const RecordedSessionInput& input,
                          const RenderOptions& options, uint64_t seed,
                          const std::string& dir);

}  // namespace kincal

#endif  // KINCAL_SYNTH_RECORDED_SESSION_H_
