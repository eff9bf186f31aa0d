#include "vision/tag_family.h"

#include <gtest/gtest.h>

#include "data/error.h"
#include "vision/apriltag_detector.h"

namespace kincal {
namespace {

TEST(TagFamily, FindsEveryKnownFamilyByName) {
  for (const char* name :
       {"tag36h11", "tag25h9", "tag16h5", "tagStandard41h12"}) {
    const TagFamilyFunctions* f = FindTagFamily(name);
    ASSERT_NE(f, nullptr) << name;
    EXPECT_STREQ(f->name, name);
    EXPECT_NE(KnownTagFamilies().find(name), std::string::npos) << name;
  }
  EXPECT_EQ(FindTagFamily("tag36h10"), nullptr);
  EXPECT_EQ(FindTagFamily(""), nullptr);
}

TEST(TagFamily, HandleCreatesTheFamilyWithItsCodes) {
  TagFamilyHandle h("tag36h11");
  ASSERT_NE(h.family, nullptr);
  EXPECT_EQ(h.family->ncodes, 587u);
  EXPECT_EQ(h.family->width_at_border, 8);
  EXPECT_EQ(TagFamilySize("tag16h5"), 30);
  EXPECT_EQ(TagBlackSquareCells("tag36h11"), 8);
  EXPECT_TRUE(IsKnownTagFamily("tag25h9"));
  EXPECT_FALSE(IsKnownTagFamily("apriltag"));
}

TEST(TagFamily, UnknownFamilyIsBadInputNamingTheKnownOnes) {
  try {
    TagFamilyHandle h("tag99h1");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tag99h1"), std::string::npos);
  }
}

TEST(TagFamily, CornersInTagFollowLibapriltagOrder) {
  // Corner k at the signs (-,+), (+,+), (+,-), (-,-) of (s/2, s/2); k mod 4.
  EXPECT_TRUE(TagCornerInTag(0, 10).isApprox(Eigen::Vector3d(-5, 5, 0)));
  EXPECT_TRUE(TagCornerInTag(1, 10).isApprox(Eigen::Vector3d(5, 5, 0)));
  EXPECT_TRUE(TagCornerInTag(2, 10).isApprox(Eigen::Vector3d(5, -5, 0)));
  EXPECT_TRUE(TagCornerInTag(3, 10).isApprox(Eigen::Vector3d(-5, -5, 0)));
  EXPECT_TRUE(TagCornerInTag(4, 10).isApprox(TagCornerInTag(0, 10)));
}

}  // namespace
}  // namespace kincal
