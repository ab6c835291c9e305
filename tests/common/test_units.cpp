#include <gtest/gtest.h>

#include "common/units.hpp"

using namespace stentsim::units;

TEST(Units, ConvertsToProjectUnits) {
  EXPECT_DOUBLE_EQ(parse_quantity("13 atm", kPressure), 13 * 0.101325);
  EXPECT_NEAR(parse_quantity("85 mmHg", kPressure), 0.0113324, 1e-7);
  EXPECT_DOUBLE_EQ(parse_quantity("1.01 MPa", kPressure), 1.01);
  EXPECT_DOUBLE_EQ(parse_quantity("156.6 kPa", kPressure), 0.1566);
  EXPECT_DOUBLE_EQ(parse_quantity("0.25 mm", kLength), 0.25);
  EXPECT_DOUBLE_EQ(parse_quantity("0.25mm", kLength), 0.25);
  EXPECT_DOUBLE_EQ(parse_quantity("40 um", kLength), 0.04);
  EXPECT_DOUBLE_EQ(parse_quantity("1e-3 m", kLength), 1.0);
  EXPECT_DOUBLE_EQ(parse_quantity("1 GPa", kPressure), 1000.0);
  EXPECT_DOUBLE_EQ(parse_quantity("1000 N/mm^3", kStiffnessPerArea), 1000.0);
  EXPECT_DOUBLE_EQ(parse_quantity("10 N/mm^2", kPressure), 10.0);
  EXPECT_DOUBLE_EQ(parse_quantity("0.08 N*mm", kMoment), 0.08);
  EXPECT_NEAR(parse_quantity("40 deg", kAngle), 0.6981317007977318, 1e-15);
  EXPECT_DOUBLE_EQ(parse_quantity("2.5", kLength), 2.5);  // bare number: project units
}

TEST(Units, RejectsWrongDimensionAndUnknownUnits) {
  EXPECT_THROW(parse_quantity("3 mm", kPressure), std::invalid_argument);
  EXPECT_THROW(parse_quantity("3 furlongs", kLength), std::invalid_argument);
  EXPECT_THROW(parse_quantity("abc", kLength), std::invalid_argument);
  EXPECT_THROW(parse_quantity("1 N/mm/s", kPressure), std::invalid_argument);
  EXPECT_THROW(parse_quantity("1 N/mm^x", kPressure), std::invalid_argument);
  try {
    parse_quantity("3 mm", kPressure);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pressure"), std::string::npos) << e.what();
  }
}
