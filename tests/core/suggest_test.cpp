#include "core/suggest.h"

#include <gtest/gtest.h>

namespace fleetmap::core {
namespace {

TEST(EditDistance, CountsInsertionsDeletionsSubstitutionsAndSwaps) {
  EXPECT_EQ(edit_distance("robots", "robots"), 0);
  EXPECT_EQ(edit_distance("robot", "robots"), 1);
  EXPECT_EQ(edit_distance("robotss", "robots"), 1);
  EXPECT_EQ(edit_distance("rebots", "robots"), 1);
  EXPECT_EQ(edit_distance("orbots", "robots"), 1);  // a swap is one edit
  EXPECT_EQ(edit_distance("ROBOTS", "robots"), 0);
  EXPECT_EQ(edit_distance("", "abc"), 3);
}

TEST(ClosestName, SuggestsTheNearestValidName) {
  const std::vector<std::string> flags = {"--robots", "--resolution", "--steps", "--seed", "--strategy"};
  EXPECT_EQ(closest_name("--robot", flags), "--robots");
  EXPECT_EQ(closest_name("--stesp", flags), "--steps");
  EXPECT_EQ(closest_name("--resol", flags), "--resolution");  // a cut flag
  EXPECT_EQ(did_you_mean("--strategyy", flags), " (did you mean '--strategy'?)");
}

TEST(ClosestName, StaysSilentWhenNothingIsClose) {
  const std::vector<std::string> merging = {"known", "rendezvous", "overlap", "landmarks"};
  EXPECT_EQ(closest_name("xyzzy", merging), std::nullopt);
  EXPECT_EQ(closest_name("known", merging), std::nullopt);  // valid already
  EXPECT_EQ(did_you_mean("graph", merging), "");
  EXPECT_EQ(closest_name("ovrlap", merging), "overlap");
}

}  // namespace
}  // namespace fleetmap::core
