#include "vision/tag_family.h"

extern "C" {
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagStandard41h12.h>
}

#include "data/error.h"
#include "vision/apriltag_detector.h"

namespace kincal {

const TagFamilyFunctions* FindTagFamily(const std::string& name) {
  static const TagFamilyFunctions kFamilies[] = {
      {"tag36h11", tag36h11_create, tag36h11_destroy},
      {"tag25h9", tag25h9_create, tag25h9_destroy},
      {"tag16h5", tag16h5_create, tag16h5_destroy},
      {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
  };
  for (const auto& f : kFamilies) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

std::string KnownTagFamilies() {
  return "tag36h11, tag25h9, tag16h5, tagStandard41h12";
}

TagFamilyHandle::TagFamilyHandle(const std::string& name) {
  fns = FindTagFamily(name);
  if (fns == nullptr) {
    throw InputError("unknown tag family '" + name +
                     "' (expected one of: " + KnownTagFamilies() + ")");
  }
  family = fns->create();
}

TagFamilyHandle::~TagFamilyHandle() {
  if (family != nullptr) fns->destroy(family);
}

Eigen::Vector3d TagCornerInTag(int k, double size_mm) {
  static const double kSign[4][2] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
  const int i = ((k % 4) + 4) % 4;
  return Eigen::Vector3d(kSign[i][0] * size_mm / 2, kSign[i][1] * size_mm / 2,
                         0.0);
}

int TagBlackSquareCells(const std::string& family) {
  TagFamilyHandle f(family);
  return f.family->width_at_border;
}

bool IsKnownTagFamily(const std::string& family) {
  return FindTagFamily(family) != nullptr;
}

int TagFamilySize(const std::string& family) {
  TagFamilyHandle f(family);
  return static_cast<int>(f.family->ncodes);
}

}  // namespace kincal
