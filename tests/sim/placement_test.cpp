#include "sim/placement.h"

#include <gtest/gtest.h>

#include <set>

#include "core/error.h"
#include "tests/sim/sim_test_maps.h"

namespace fleetmap::sim {
namespace {

using mapping::CellState;

// A 6 x 6 m room (0.1 m cells) with a closed 2 x 2 m box in the middle of the map: the box's
// inside is free but no robot can drive from it to the room. The map's centre lies in the box.
mapping::OccupancyGrid room_with_a_closed_box() {
  auto g = testing::walled_room(60, 60);
  for (int i = 20; i <= 40; ++i) {
    g.set_state({i, 20}, CellState::Occupied), g.set_state({i, 40}, CellState::Occupied);
    g.set_state({20, i}, CellState::Occupied), g.set_state({40, i}, CellState::Occupied);
  }
  return g;
}

int region_of(const World& world, const ReachableRegions& regions, const core::Pose2& p) {
  return regions.at(world.geometry().index(*world.geometry().world_to_cell(p.position())));
}

TEST(ReachableRegions, SplitsWhereARobotCannotDriveThrough) {
  const World world(room_with_a_closed_box(), {});
  const auto regions = world.reachable_regions(0.2);
  ASSERT_EQ(regions.cells.size(), 2u);  // the room around the box, and the box's inside
  const auto& g = world.geometry();
  const int room = regions.at(g.index({5, 5})), box = regions.at(g.index({30, 30}));
  EXPECT_EQ(regions.largest, room);
  EXPECT_NE(room, box);
  EXPECT_EQ(regions.at(g.index({20, 30})), -1);  // a wall
  EXPECT_EQ(regions.at(g.index({2, 30})), -1);   // too near the outer wall for a robot of radius 0.2 m
  EXPECT_GT(regions.cells[std::size_t(room)], 5 * regions.cells[std::size_t(box)]);
}

TEST(Placement, ClusteredAndRandomStartsAreAllInTheLargestRegionWhereverTheCentreIs) {
  const World world(room_with_a_closed_box(), {});
  const auto regions = world.reachable_regions(0.2);
  for (const Placement placement : {Placement::Cluster, Placement::Random}) {
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      Scenario s;
      s.placement = placement;
      s.robot_count = 4;
      core::Random rng(seed);
      for (const auto& p : place_robots(s, world, rng)) {
        EXPECT_EQ(region_of(world, regions, p), regions.largest) << "seed " << seed << " at " << p.x << "," << p.y;
        EXPECT_TRUE(world.disc_free(p.position(), s.robot.radius_m));
      }
    }
  }
}

TEST(Placement, ClusterAtChoosesTheRegionAroundThePoint) {
  const World world(room_with_a_closed_box(), {});
  const auto regions = world.reachable_regions(0.2);
  Scenario s;
  s.robot_count = 2;
  s.cluster_at = Eigen::Vector2d(3.05, 3.05);  // inside the box
  core::Random rng(1);
  const auto starts = place_robots(s, world, rng);
  ASSERT_EQ(starts.size(), 2u);
  for (const auto& p : starts) EXPECT_EQ(region_of(world, regions, p), regions.at(world.geometry().index({30, 30})));
  // More robots than the box holds: refused, naming the point.
  s.robot_count = 20;
  try {
    core::Random again(1);
    place_robots(s, world, again);
    FAIL() << "twenty robots do not fit in the box";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("around (3.05, 3.05)"), std::string::npos) << e.what();
  }
}

TEST(Placement, ARobotThatFitsNowhereIsRefused) {
  const World world(testing::walled_room(5, 5), {});  // 0.3 m of free space across
  Scenario s;
  s.robot_count = 1;
  core::Random rng(1);
  EXPECT_THROW(place_robots(s, world, rng), InputError);
}

TEST(ObservableSpace, CountsTheRegionsTheStartsAreInAndTheLargestRegion) {
  const World world(room_with_a_closed_box(), {});
  const auto& g = world.geometry();
  const auto both = world.observable_space({g.cell_center({5, 5}), g.cell_center({30, 30})}, 0.2, 4.0);
  EXPECT_EQ(both.start_regions, 2);
  const auto box = world.observable_space({g.cell_center({30, 30})}, 0.2, 4.0);
  EXPECT_EQ(box.start_regions, 1);
  EXPECT_LT(box.poses, box.largest_region_poses);
  const auto room = world.observable_space({g.cell_center({5, 5})}, 0.2, 4.0);
  EXPECT_EQ(room.poses, room.largest_region_poses);
}

}  // namespace
}  // namespace fleetmap::sim
