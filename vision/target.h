#ifndef KINCAL_VISION_TARGET_H_
#define KINCAL_VISION_TARGET_H_

// The tool target: AprilTags fixed on the needle holder and the needle tip,
// all in the `tool` frame (target.yaml, ../shared/spec/formats.md):
//
//   kincal_target: 1
//   family: tag36h11
//   tags:                 # size = edge of the tag's black square, mm
//     - {id: 0, size: 30.0, tool_from_tag: {R: [9 numbers, row-major], t: [x,
//     y, z]}}
//   tip_in_tool: [0, 0, 150]
//
// Tag frame: origin at the centre, x right, y down the printed image, z into
// the tag; the black square spans [-size/2, size/2] in x and y.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "camcal/camera_model.h"

namespace kincal {

struct TargetTag {
  int id = 0;
  double size_mm = 0;  // edge of the black square
  Rigid3 tool_from_tag;
  // Measured targets (kincal target): 1-sigma of the pose, translation in
  // the tool frame (mm) and rotation vector of the error in the tool frame
  // (deg). Written as `sigma: {t_mm: [...], r_deg: [...]}` when has_sigma.
  bool has_sigma = false;
  Eigen::Vector3d sigma_t_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_r_deg = Eigen::Vector3d::Zero();

  // Corner k (libapriltag's order, see vision/apriltag_detector.h) in `tool`.
  Eigen::Vector3d CornerInTool(int k) const;
};

struct Target {
  std::string family = "tag36h11";
  std::vector<TargetTag> tags;
  Eigen::Vector3d tip_in_tool = Eigen::Vector3d::Zero();
  // False for a board without a tip (tip_in_tool absent from the file; it
  // then reads as the tool origin).
  bool has_tip = true;
  // Measured tip: 1-sigma per tool axis, mm (`tip_sigma_mm`).
  bool has_tip_sigma = false;
  Eigen::Vector3d tip_sigma_mm = Eigen::Vector3d::Zero();
  // The command line that measured the target (`made_by`); empty = none.
  std::string made_by;

  // nullptr when the target has no tag with this id.
  const TargetTag* FindTag(int id) const;
};

// Reads target.yaml (version 1, with the optional measured-target fields of
// format version 3: per-tag `sigma`, `tip_sigma_mm`, `made_by`, and
// `tip_in_tool` optional). Strict: unknown keys, a missing field, a
// duplicate id, an id outside the family, a non-positive size or a matrix
// that is not a rotation raise InputError with file:line:column. R may be
// rounded (orthonormal within 1e-3); it is replaced by the nearest rotation.
// How kincal's synthetic sessions and the planner mount a target on the
// robot: the tool frame relative to the needle-tip frame (the last row of
// the chain), with the needle (tip z) running along tool y from the tags to
// the tip and tool z (into the tags) along tip x. tip_from_tool maps tool
// points to the tip frame. Real tools are mounted as they are: the bundle
// estimates flange_from_target instead of assuming this.
Rigid3 TipFromTool(const Target& target);

Target ReadTargetYaml(const std::string& path);
Target ParseTargetYaml(const std::string& text, const std::string& file_label);

// target.yaml text with the provenance comment; Write is atomic.
std::string FormatTargetYaml(const Target& target);
void WriteTargetYaml(const std::string& path, const Target& target);

}  // namespace kincal

#endif  // KINCAL_VISION_TARGET_H_
