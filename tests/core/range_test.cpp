#include "core/range.h"

#include <gtest/gtest.h>

#include <limits>

namespace fleetmap::core {
namespace {

TEST(Range, AcceptsExactlyTheNumbersInsideAndSaysWhichInOneWay) {
  const Range beams{1, 100000, true};
  EXPECT_EQ(parse_in_range("360", beams), 360.0);
  EXPECT_EQ(parse_in_range("100000", beams), 100000.0);
  for (const char* bad : {"0", "100001", "1.5", "-3", "nan", "inf", "", " 4", "4 ", "0x10", "many", "1e300"}) {
    EXPECT_FALSE(parse_in_range(bad, beams)) << bad;
  }
  EXPECT_EQ(expected_text(beams), "a whole number from 1 to 100000");
  const Range range{1e-3, 1e6};
  EXPECT_EQ(parse_in_range("1e-3", range), 1e-3);
  EXPECT_EQ(parse_in_range("+2.5", range), 2.5);
  EXPECT_FALSE(parse_in_range("1e-9", range));
  EXPECT_EQ(expected_text(range), "a number >= 0.001 and <= 1000000");
  const Range comm{0, std::numeric_limits<double>::infinity(), false, true};
  EXPECT_EQ(parse_in_range("inf", comm), std::numeric_limits<double>::infinity());
  EXPECT_EQ(parse_in_range(".inf", comm), std::numeric_limits<double>::infinity());
  EXPECT_FALSE(parse_in_range("-1", comm));
  EXPECT_FALSE(parse_in_range("nan", comm));
  EXPECT_EQ(expected_text(comm), "a number >= 0 (or inf)");
}

TEST(Range, SeedsAreEvery64BitNumberAndNothingElse) {
  EXPECT_EQ(parse_seed("0"), 0u);
  EXPECT_EQ(parse_seed("18446744073709551615"), std::numeric_limits<std::uint64_t>::max());
  for (const char* bad : {"18446744073709551616", "99999999999999999999", "-1", "+1", "1e3", "", "1.0", " 1"}) {
    EXPECT_FALSE(parse_seed(bad)) << bad;
  }
}

}  // namespace
}  // namespace fleetmap::core
