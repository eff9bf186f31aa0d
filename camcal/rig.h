#ifndef KINCAL_CAMCAL_RIG_H_
#define KINCAL_CAMCAL_RIG_H_

// The camera rig file `rig.yaml` (../shared/spec/formats.md, "Camera rig"):
//
//   kincal_rig: 1
//   mount: world        # optional (format v3): world (default) | flange
//   cameras:            # 1..N cameras; first = reference; rig frame = its
//   frame
//     - name: left
//       width: 1280
//       height: 1024
//       fx: 1800.0
//       fy: 1800.0
//       cx: 639.5       # OpenCV pixel centres
//       cy: 511.5
//       distortion: [k1, k2, p1, p2, k3]   # 0, 4, 5 or 8 numbers
//       cam_from_rig: {R: [9 numbers, row-major], t: [x, y, z]}   # t in mm
//       valid_intrinsics_region: [[u, v], ...]   # optional, px, closed
//
// mount: where the cameras are. `world`: on a stand, the target on the
// robot's flange (the bundle estimates rig_from_base and flange_from_target);
// `flange`: on the robot's flange, the target fixed in the world (the bundle
// estimates flange_from_rig and base_from_target). Written only when flange,
// so a stand rig's file reads as format version 2 wrote it.
//
// valid_intrinsics_region (optional): the outline of the image region where
// the projection uncertainty stays below camcal's threshold (mrcal's
// valid_intrinsics_region; see camcal/projection_uncertainty.h); absent or
// empty when unknown.

#include <string>
#include <vector>

#include "camcal/camera_model.h"

namespace kincal {

struct Camera {
  CameraIntrinsics intrinsics;
  Rigid3 cam_from_rig;  // p_in_cam = cam_from_rig * p_in_rig, t in mm
  std::vector<Eigen::Vector2d> valid_intrinsics_region;  // px; may be empty
};

enum class RigMount { kWorld, kFlange };

// "world" | "flange".
const char* RigMountName(RigMount mount);

struct Rig {
  std::vector<Camera> cameras;  // cameras[0].cam_from_rig = identity
  RigMount mount = RigMount::kWorld;

  // Camera names in rig order.
  std::vector<std::string> CameraNames() const;
  // Index of the camera called `name`; -1 when none.
  int FindCamera(const std::string& name) const;

  // Distance between the first two camera centres (mm); 0 with one camera.
  double BaselineMm() const;
};

// Parses rig.yaml text. `file` is used in messages. Strict: unknown keys,
// a `mount` other than world | flange, wrong counts, non-positive focal lengths
// or sizes, duplicate names, a non-rotation R, or a first camera that is not
// the rig frame raise InputError with file:line:column. R is accepted when
// orthonormal to 1e-4 (hand-typed files) and then projected onto the nearest
// rotation.
Rig ParseRigYaml(const std::string& text, const std::string& file);
Rig ReadRigYaml(const std::string& path);

// YAML text of `rig`, with a "# written by kincal ...: <command line>"
// comment first and every number written so that it reads back exactly.
std::string RigToYaml(const Rig& rig);
// Writes RigToYaml(rig) atomically (data/atomic_file.h).
void WriteRigYaml(const std::string& path, const Rig& rig);

}  // namespace kincal

#endif  // KINCAL_CAMCAL_RIG_H_
