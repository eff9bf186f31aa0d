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

  // Corner k (libapriltag's order, see vision/apriltag_detector.h) in `tool`.
  Eigen::Vector3d CornerInTool(int k) const;
};

struct Target {
  std::string family = "tag36h11";
  std::vector<TargetTag> tags;
  Eigen::Vector3d tip_in_tool = Eigen::Vector3d::Zero();

  // nullptr when the target has no tag with this id.
  const TargetTag* FindTag(int id) const;
};

// Reads target.yaml (version 1). Strict: unknown keys, a missing field, a
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
