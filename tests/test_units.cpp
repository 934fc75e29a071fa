#include <gtest/gtest.h>

#include <cmath>

#include "units.hpp"

using namespace quadgen;

TEST(Units, ParsesCompoundUnits) {
  EXPECT_EQ(parse_unit("N").dim.str(), "m kg s^-2");
  EXPECT_EQ(parse_unit("kg m^2").dim.str(), "m^2 kg");
  EXPECT_EQ(parse_unit("N s^2/m").dim, parse_unit("kg").dim);
  EXPECT_NEAR(parse_unit("rpm").scale, 2 * M_PI / 60, 1e-15);
  EXPECT_NEAR(parse_unit("mm").scale, 1e-3, 1e-18);
  EXPECT_THROW(parse_unit("furlong"), UnitError);
  EXPECT_THROW(parse_unit("m^x"), UnitError);
}
