#include "cli/sweep_flags.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_support.h"

namespace fleetmap::cli {
namespace {

using fleetmap::testing::expect_input_error;

TEST(SweepFlags, FlagsReplaceTheSweepFilesValues) {
  sweep::Sweep s = sweep::parse_sweep("maps: [office, cave]\nrobots: [1, 2]\nmerging: rendezvous\n", "s.yaml", "");
  SweepFlags flags;
  flags.robots = "9";
  flags.steps = 50;
  flags.comm_range = "inf";
  flags.merging = "overlap";
  sweep::Sweep o = s;
  apply_sweep_flags(o, flags);
  EXPECT_EQ(o.base.merging, "overlap");
  EXPECT_EQ(o.robots, (std::vector<int>{9}));
  EXPECT_EQ(o.base.steps, 50);
  EXPECT_TRUE(std::isinf(o.base.communication.range_m));
  EXPECT_EQ(o.maps, s.maps);
  SweepFlags bad;
  bad.merging = "telepathy";
  expect_input_error([&] { apply_sweep_flags(o, bad); }, {"--merging", "telepathy"});
}

TEST(SweepFlags, ShardFlagIsChecked) {
  const sweep::Shard s = parse_shard("2/4");
  EXPECT_EQ(s.index, 2);
  EXPECT_EQ(s.count, 4);
  for (const char* bad : {"5/4", "0/3", "3", "a/b", "1/0", "-1/3", "2/", "/4", "1/2/3", ""}) {
    expect_input_error([&] { parse_shard(bad); }, {"--shard", "K/N"});
  }
}

}  // namespace
}  // namespace fleetmap::cli
