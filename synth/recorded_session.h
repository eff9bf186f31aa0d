#ifndef KINCAL_SYNTH_RECORDED_SESSION_H_
#define KINCAL_SYNTH_RECORDED_SESSION_H_

// Renders a recorded session in the spec's layout (../shared/spec/formats.md
// v2, "Recorded session"; data/session.h reads it back):
//
//   DIR/left/000000.png ...  right/000000.png ...   8-bit gray, lossless
//   DIR/frames.csv    frame,t_left,t_right,seq_left,seq_right,<joints>
//   DIR/session.yaml  kincal_session: 1, status: complete, ...
//   DIR/truth.csv     frame, rig_from_tool (R row-major, t mm), tip in rig
//   DIR/corners.csv   frame, camera, tag, corner, u, v, visible (px)
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
// Returns the number of frames. InputError for bad options, a folder that is
// not writable or already has frames.csv.
int RenderRecordedSession(const Rig& rig, const Target& target,
                          const RecordedSessionInput& input,
                          const RenderOptions& options, uint64_t seed,
                          const std::string& dir);

}  // namespace kincal

#endif  // KINCAL_SYNTH_RECORDED_SESSION_H_
