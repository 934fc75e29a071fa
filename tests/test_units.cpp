#include <gtest/gtest.h>

#include <cmath>

#include "model/units.hpp"

using namespace quadgen;

TEST(Units, ParsesCompoundUnits) {
  EXPECT_EQ(parse_unit("N").dim.str(), "m kg s^-2");
  EXPECT_EQ(parse_unit("kg m^2").dim.str(), "m^2 kg");
  EXPECT_EQ(parse_unit("N s^2/m").dim, parse_unit("kg").dim);
  EXPECT_NEAR(parse_unit("rpm").scale, 2 * M_PI / 60, 1e-15);
  EXPECT_NEAR(parse_unit("mm").scale, 1e-3, 1e-18);
  EXPECT_THROW(parse_unit("furlong"), UnitError);
  EXPECT_THROW(parse_unit("m^x"), UnitError);
  // Separators alone read as 1, or as the one factor beside them (a review, helper-135).
  for (const char* bad : {" ", "/", "*", "** mm*/", "m/", "/s"}) EXPECT_THROW(parse_unit(bad), UnitError) << bad;
  EXPECT_EQ(parse_unit("1/s").dim, parse_unit("s^-1").dim);
}

// Exponents are parsed without std::stoi (whose overflow would reach Dimension::pow as UB)
// and bounded, per factor and for the unit as a whole.
TEST(Units, RefusesExponentsBeyondTheBound) {
  EXPECT_EQ(parse_unit("m^12").dim.exp[0], 12);
  EXPECT_EQ(parse_unit("s^-12").dim.exp[2], -12);
  EXPECT_EQ(parse_unit("m^+2").dim.exp[0], 2);
  for (const char* bad : {"m^13", "m^-13", "m^2147483647", "m^-2147483648", "m^99999999999999999999", "m^", "m^-", "m^1.5"})
    EXPECT_THROW(parse_unit(bad), UnitError) << bad;
  EXPECT_THROW(parse_unit("m^12 m^12"), UnitError);  // combined exponent 24
  try {
    parse_unit("m^2147483647");
    FAIL();
  } catch (const UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
}

// rad is dimensionless, so Hz would pass for rad/s whatever it meant: it is refused, with
// the two unambiguous spellings suggested; rev is 2 pi rad, consistent with rpm.
TEST(Units, RefusesHzAndOffersRevPerSecond) {
  for (const char* bad : {"Hz", "1/Hz", "N/Hz", "Hz^2"}) {
    try {
      parse_unit(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const UnitError& e) {
      EXPECT_NE(std::string(e.what()).find("rev/s"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("1/s"), std::string::npos) << e.what();
    }
  }
  EXPECT_NEAR(parse_unit("rev/s").scale, 2 * M_PI, 1e-15);
  EXPECT_NEAR(parse_unit("rev/min").scale, parse_unit("rpm").scale, 1e-15);
  EXPECT_EQ(parse_unit("rev/s").dim, parse_unit("rad/s").dim);
  EXPECT_EQ(parse_unit("1/s").scale, 1.0);
}
