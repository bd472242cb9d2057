// The advisor's symmetry look (runner/advise.h, issue 9): a mesh that maps
// onto itself under a rotation gets a warning naming it, an asymmetric one
// none.
#include <gtest/gtest.h>

#include "models/procedural.h"
#include "runner/advise.h"

namespace {

TEST(AdviseSymmetry, ACylinderTurnsFreelyAboutItsAxis) {
  const std::string w = pb::symmetry_warning(pb::make_cylinder(35, 120), 1);
  EXPECT_NE(w.find("every rotation about z"), std::string::npos) << w;
  EXPECT_EQ(w.find("every rotation about x"), std::string::npos) << w;
  EXPECT_NE(w.find("1/2 turn about x"), std::string::npos) << w;  // upside down
}

TEST(AdviseSymmetry, ABoxHasHalfTurnsAboutEachAxis) {
  const std::string w = pb::symmetry_warning(pb::make_box(120, 80, 60), 1);
  for (const char* axis : {"x", "y", "z"})
    EXPECT_NE(w.find(std::string("1/2 turn about ") + axis), std::string::npos) << axis << ": " << w;
  EXPECT_EQ(w.find("1/4 turn"), std::string::npos) << w;  // 120 x 80 is not square
  EXPECT_EQ(w.find("every rotation"), std::string::npos) << w;
}

TEST(AdviseSymmetry, TheMilkCartonsGableAllowsOnlyAHalfTurnAboutZ) {
  const std::string w = pb::symmetry_warning(pb::make_milk_carton(), 1);
  EXPECT_NE(w.find("1/2 turn about z"), std::string::npos) << w;
  EXPECT_EQ(w.find("about x"), std::string::npos) << w;
  EXPECT_EQ(w.find("about y"), std::string::npos) << w;
}

}  // namespace
