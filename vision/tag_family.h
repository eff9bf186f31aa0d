#ifndef KINCAL_VISION_TAG_FAMILY_H_
#define KINCAL_VISION_TAG_FAMILY_H_

// libapriltag's tag families by name (internal to vision/). Kept apart from
// the detector so that reading a target.yaml (vision/target.cc) needs
// libapriltag's family tables only, not OpenCV: bin/kincal, which reads no
// images, then loads no OpenCV library (app/front_end.h). The public
// functions on families (TagCornerInTag, IsKnownTagFamily, TagFamilySize,
// TagBlackSquareCells) are declared in vision/apriltag_detector.h and
// defined in tag_family.cc.

extern "C" {
#include <apriltag/apriltag.h>
}

#include <string>

namespace kincal {

struct TagFamilyFunctions {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

// nullptr for an unknown name.
const TagFamilyFunctions* FindTagFamily(const std::string& name);

// "tag36h11, tag25h9, ..." for messages.
std::string KnownTagFamilies();

// A family instance that destroys itself; InputError for an unknown name.
struct TagFamilyHandle {
  explicit TagFamilyHandle(const std::string& name);
  ~TagFamilyHandle();
  TagFamilyHandle(const TagFamilyHandle&) = delete;
  TagFamilyHandle& operator=(const TagFamilyHandle&) = delete;
  const TagFamilyFunctions* fns = nullptr;
  apriltag_family_t* family = nullptr;
};

}  // namespace kincal

#endif  // KINCAL_VISION_TAG_FAMILY_H_
