#include "motion/units.h"

#include <gtest/gtest.h>

#include "motion/roles.h"

namespace throng::motion {
namespace {

TEST(Units, NamesAndFactors) {
  for (LengthUnit u :
       {LengthUnit::Metre, LengthUnit::Centimetre, LengthUnit::Millimetre, LengthUnit::Inch, LengthUnit::CmuAsf})
    EXPECT_EQ(parse_length_unit(to_string(u)), u);
  EXPECT_EQ(parse_length_unit("Inches"), LengthUnit::Inch);
  EXPECT_FALSE(parse_length_unit("furlong").has_value());
  EXPECT_DOUBLE_EQ(metres_per_unit(LengthUnit::Inch), 0.0254);
  EXPECT_NEAR(metres_per_unit(LengthUnit::CmuAsf), 0.056444, 1e-6);  // the CMU FAQ's figure
}

Skeleton figure(double scale, bool named_legs) {
  Skeleton s;
  s.add_joint("Hips", -1, glm::vec3(0.0f));
  s.add_joint(named_legs ? "LeftUpLeg" : "a", 0, glm::vec3(0.1, 0, 0) * static_cast<float>(scale));
  s.add_joint(named_legs ? "LeftLeg" : "b", 1, glm::vec3(0, -0.44, 0) * static_cast<float>(scale));
  s.add_joint(named_legs ? "LeftFoot" : "c", 2, glm::vec3(0, -0.43, 0) * static_cast<float>(scale));
  s.add_joint("Spine", 0, glm::vec3(0, 0.8, 0) * static_cast<float>(scale));
  assign_roles(s);
  return s;
}

TEST(Units, GuessFromLegsOrExtent) {
  for (bool legs : {true, false})
    for (LengthUnit u :
         {LengthUnit::Metre, LengthUnit::Centimetre, LengthUnit::Millimetre, LengthUnit::Inch, LengthUnit::CmuAsf}) {
      const UnitGuess g = guess_length_unit(figure(1.0 / metres_per_unit(u), legs));
      EXPECT_EQ(g.unit, u) << to_string(u) << " legs " << legs;
      EXPECT_EQ(g.from_legs, legs);
    }
  Skeleton point;
  point.add_joint("only", -1, glm::vec3(0.0f));
  EXPECT_EQ(guess_length_unit(point).unit, LengthUnit::Metre);  // nothing to measure
}

}  // namespace
}  // namespace throng::motion
