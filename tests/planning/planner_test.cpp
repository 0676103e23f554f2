// One harness for every registered planner, by name: the same queries, success and validity for
// each. OMPL planners get budgets far above what they need, and no test asserts a time.
#include "planning/planner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/random.h"
#include "maps/builtin_maps.h"
#include "tests/planning/planning_test_support.h"
#include "tests/test_support.h"

namespace fleetmap::planning {
namespace {

using testing::grid_from_ascii;
using testing::path_clear_of_obstacles;

constexpr double kRadius = 0.2;
constexpr double kBudget = 1.0;

struct Query {
  Eigen::Vector2d start, goal;
};

PlannerInfo info_of(const std::string& name) {
  const std::vector<PlannerInfo> infos = planner_infos();
  return *std::find_if(infos.begin(), infos.end(), [&](const PlannerInfo& i) { return i.name == name; });
}

// A walled 8 x 5 m field with a few pillars: every planner, the reactive one included, gets across.
const mapping::OccupancyGrid& pillar_field() {
  static const mapping::OccupancyGrid grid = [] {
    mapping::OccupancyGrid g = testing::walled_room(80, 50);
    for (const auto& [cx, cy] : {std::pair{25, 25}, {45, 15}, {45, 37}, {62, 26}}) {
      for (int y = cy - 3; y <= cy + 3; ++y)
        for (int x = cx - 3; x <= cx + 3; ++x) g.set_state({x, y}, mapping::CellState::Occupied);
    }
    return g;
  }();
  return grid;
}

const mapping::OccupancyGrid& office() {
  static const mapping::OccupancyGrid grid = maps::load_map_source("office");
  return grid;
}

// Seeded random pairs of valid points, at least `min_distance` apart, joined by free space.
std::vector<Query> random_queries(const mapping::OccupancyGrid& grid, int count, double min_distance, std::uint64_t seed) {
  const FreeSpace space(grid, {kRadius, UnknownCells::Obstacle});
  core::Random rng(seed);
  const auto& g = grid.geometry();
  std::vector<Query> queries;
  while (static_cast<int>(queries.size()) < count) {
    const Eigen::Vector2d a(rng.uniform(0, g.width_m()), rng.uniform(0, g.height_m()));
    const Eigen::Vector2d b(rng.uniform(0, g.width_m()), rng.uniform(0, g.height_m()));
    if (!space.valid(a) || !space.valid(b) || (a - b).norm() < min_distance) continue;
    if (!space.connected(*g.world_to_cell(a), *g.world_to_cell(b))) continue;
    queries.push_back({a, b});
  }
  return queries;
}

void expect_valid_success(const PlanResult& r, const mapping::OccupancyGrid& grid, const Query& q, double radius,
                          bool unknown_blocks = true) {
  ASSERT_TRUE(r.success()) << r.planner << ": " << r.status << ": " << r.detail;
  ASSERT_GE(r.path.size(), 2u);
  EXPECT_EQ(r.path.front(), q.start);
  EXPECT_EQ(r.path.back(), q.goal);
  EXPECT_TRUE(path_clear_of_obstacles(grid, r.path, radius, unknown_blocks)) << r.planner;
  EXPECT_NEAR(r.length_m, path_length(r.path), 1e-9);
  EXPECT_GE(r.length_m, (q.goal - q.start).norm() - 1e-9);
  ASSERT_TRUE(r.first_solution_s.has_value()) << r.planner;
  EXPECT_LE(*r.first_solution_s, r.time_s);
}

class EveryPlanner : public ::testing::TestWithParam<std::string> {
 protected:
  PlanResult plan(const mapping::OccupancyGrid& grid, const Query& q, const FreeSpaceOptions& space_options = {},
                  PlannerOptions options = {}) {
    options.time_budget_s = kBudget;
    const FreeSpace space(grid, space_options);
    auto planner = make_planner(GetParam());
    EXPECT_EQ(planner->name(), GetParam());
    return planner->plan(space, q.start, q.goal, options);
  }
};

TEST_P(EveryPlanner, CrossesAPillarField) {
  const std::vector<Query> queries = {
      {{0.5, 2.5}, {7.5, 2.5}}, {{0.6, 0.6}, {7.4, 4.4}}, {{7.2, 0.5}, {0.5, 4.5}}, {{2.5, 4.2}, {6.3, 0.7}}};
  for (const Query& q : queries) {
    SCOPED_TRACE(::testing::Message() << "from " << q.start.transpose() << " to " << q.goal.transpose());
    expect_valid_success(plan(pillar_field(), q), pillar_field(), q, kRadius);
  }
}

TEST_P(EveryPlanner, PlansBetweenOfficeRooms) {
  for (const Query& q : random_queries(office(), 3, 8.0, 17)) {
    SCOPED_TRACE(::testing::Message() << "from " << q.start.transpose() << " to " << q.goal.transpose());
    const PlanResult r = plan(office(), q);
    if (info_of(GetParam()).complete || r.success()) {
      expect_valid_success(r, office(), q, kRadius);
    } else {
      EXPECT_EQ(r.status, PlanStatus::NotFound) << r.detail;
      EXPECT_TRUE(r.path.empty());
    }
  }
}

TEST_P(EveryPlanner, ReportsBadEndpointsAsOutcomes) {
  const auto grid = grid_from_ascii({
      "####################",
      "#..................#",
      "#..................#",
      "#.......####.......#",
      "#.......####.......#",
      "#.......####.....???",
      "#..................?",
      "#..................?",
      "####################",
  });
  const Eigen::Vector2d inside(0.45, 0.35);
  EXPECT_EQ(plan(grid, {{-1.0, 0.35}, inside}).status, PlanStatus::StartOutsideMap);
  EXPECT_EQ(plan(grid, {inside, {0.45, 12.0}}).status, PlanStatus::GoalOutsideMap);
  const PlanResult wall = plan(grid, {inside, {0.95, 0.45}});  // in the block
  EXPECT_EQ(wall.status, PlanStatus::GoalInObstacle);
  EXPECT_NE(wall.detail.find("inside an obstacle"), std::string::npos) << wall.detail;
  const PlanResult close = plan(grid, {{0.15, 0.35}, inside});  // 0.1 m from the wall, radius 0.2
  EXPECT_EQ(close.status, PlanStatus::StartInObstacle);
  EXPECT_NE(close.detail.find("robot radius"), std::string::npos) << close.detail;
  const PlanResult unknown = plan(grid, {inside, {1.95, 0.35}}, {0.0, UnknownCells::Obstacle});
  EXPECT_EQ(unknown.status, PlanStatus::GoalInObstacle);
  EXPECT_NE(unknown.detail.find("unknown"), std::string::npos) << unknown.detail;
  for (const PlanResult& r : {wall, close, unknown}) {
    EXPECT_FALSE(r.success());
    EXPECT_TRUE(r.path.empty());
    EXPECT_EQ(r.detail.find('\n'), std::string::npos);
  }
  // Start and goal in one spot: a path of length 0.
  const PlanResult same = plan(grid, {inside, inside});
  ASSERT_TRUE(same.success()) << same.detail;
  EXPECT_NEAR(same.length_m, 0.0, 1e-12);
}

TEST_P(EveryPlanner, AnImpossibleQueryAnswersNoPath) {
  // Two rooms without a door.
  const auto grid = grid_from_ascii({
      "#########################",
      "#..........#............#",
      "#..........#............#",
      "#..........#............#",
      "#..........#............#",
      "#..........#............#",
      "#..........#............#",
      "#########################",
  });
  const Query q{{0.55, 0.45}, {1.85, 0.45}};
  const PlanResult quick = plan(grid, q);
  EXPECT_EQ(quick.status, PlanStatus::Unreachable) << quick.detail;
  EXPECT_NE(quick.detail.find("cannot be reached"), std::string::npos) << quick.detail;
  // Without the reachability check the planner itself must give up within its budget.
  PlannerOptions search;
  search.check_reachability = false;
  const PlanResult slow = plan(grid, q, {}, search);
  EXPECT_TRUE(slow.status == PlanStatus::Unreachable || slow.status == PlanStatus::NotFound) << slow.status;
  EXPECT_FALSE(slow.success());
  EXPECT_TRUE(slow.path.empty());
  EXPECT_FALSE(slow.detail.empty());
}

TEST_P(EveryPlanner, UnknownCellsAreFreeOnlyByOption) {
  // The only way between the halves runs through unknown cells.
  const auto grid = grid_from_ascii({
      "##############################",
      "#.............?..............#",
      "#.............?..............#",
      "#.............?..............#",
      "#.............?..............#",
      "#.............?..............#",
      "#.............?..............#",
      "#.............?..............#",
      "##############################",
  });
  const Query q{{0.45, 0.45}, {2.45, 0.45}};
  EXPECT_EQ(plan(grid, q, {kRadius, UnknownCells::Obstacle}).status, PlanStatus::Unreachable);
  expect_valid_success(plan(grid, q, {kRadius, UnknownCells::Free}), grid, q, kRadius, false);
}

INSTANTIATE_TEST_SUITE_P(AllPlanners, EveryPlanner, ::testing::ValuesIn(planner_names()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

TEST(PlannerRegistry, ListsEveryPlannerOnce) {
  const std::vector<std::string> names = planner_names();
  for (const char* expected : {"rrtstar", "informedrrtstar", "prmstar", "rrtconnect", "bitstar", "astar", "reactive"}) {
    EXPECT_EQ(std::count(names.begin(), names.end(), expected), 1) << expected;
    EXPECT_NE(planner_help().find(std::string("  ") + expected + ": "), std::string::npos) << expected;
  }
  EXPECT_FALSE(info_of("reactive").complete);
  EXPECT_TRUE(info_of("astar").complete);
  for (const auto& name : names) EXPECT_EQ(make_planner(name)->name(), name);
}

TEST(PlannerRegistry, MisuseThrowsInputError) {
  fleetmap::testing::expect_input_error([] { make_planner("rrtstr"); }, {"unknown planner 'rrtstr'", "rrtstar", "astar"});
  const auto grid = testing::walled_room(20, 20);
  const FreeSpace space(grid);
  PlannerOptions options;
  options.time_budget_s = 0.0;
  fleetmap::testing::expect_input_error([&] { make_planner("astar")->plan(space, {0.5, 0.5}, {1.5, 1.5}, options); },
                                        {"time budget", "a number >= 0.001 and <= 3600"});
}

TEST(PlanPath, PlansOnAGridInOneCall) {
  PlanPathOptions options;
  options.planner = "astar";
  options.space.robot_radius_m = 0.3;
  const Query q{{0.5, 0.5}, {7.5, 4.5}};
  const PlanResult r = plan_path(pillar_field(), q.start, q.goal, options);
  expect_valid_success(r, pillar_field(), q, 0.3);
  EXPECT_EQ(r.planner, "astar");
  options.planner = "nosuch";
  fleetmap::testing::expect_input_error([&] { plan_path(pillar_field(), q.start, q.goal, options); }, {"nosuch"});
}

TEST(Planners, WorkOnARotatedAndShiftedMap) {
  // The pillar field with its lower-left corner at (-3, 2), turned by 0.4 rad.
  const mapping::OccupancyGrid& field = pillar_field();
  const core::GridGeometry turned(0.1, field.width(), field.height(), core::Pose2(-3.0, 2.0, 0.4));
  mapping::OccupancyGrid grid(turned);
  for (int y = 0; y < grid.height(); ++y)
    for (int x = 0; x < grid.width(); ++x) grid.set_state({x, y}, field.state({x, y}));
  const FreeSpace space(grid, {kRadius, UnknownCells::Obstacle});
  const Query q{turned.grid_to_world({5.0, 5.0}), turned.grid_to_world({75.0, 45.0})};
  PlannerOptions options;
  options.time_budget_s = kBudget;
  for (const std::string name : {"astar", "rrtconnect", "rrtstar"}) {
    const PlanResult r = make_planner(name)->plan(space, q.start, q.goal, options);
    expect_valid_success(r, grid, q, kRadius);
  }
  EXPECT_EQ(make_planner("astar")->plan(space, {0.5, 0.5}, q.goal, options).status, PlanStatus::StartOutsideMap);
}

TEST(OmplPlanners, TheSameSeedGivesTheSamePath) {
  const FreeSpace space(office(), {kRadius, UnknownCells::Obstacle});
  const Query q = random_queries(office(), 1, 10.0, 5).front();
  PlannerOptions options;
  options.time_budget_s = 5.0;
  options.simplify = false;  // simplification runs against the clock
  options.seed = 11;
  const PlanResult a = make_planner("rrtconnect")->plan(space, q.start, q.goal, options);
  const PlanResult b = make_planner("rrtconnect")->plan(space, q.start, q.goal, options);
  ASSERT_TRUE(a.success()) << a.detail;
  ASSERT_TRUE(b.success()) << b.detail;
  EXPECT_EQ(a.path, b.path);
  options.seed = 12;
  const PlanResult c = make_planner("rrtconnect")->plan(space, q.start, q.goal, options);
  ASSERT_TRUE(c.success()) << c.detail;
  EXPECT_NE(a.path, c.path);
}

TEST(OmplPlanners, SimplificationShortensPaths) {
  const FreeSpace space(office(), {kRadius, UnknownCells::Obstacle});
  PlannerOptions options;
  options.time_budget_s = 5.0;
  double raw = 0, simplified = 0;
  for (const Query& q : random_queries(office(), 5, 8.0, 23)) {
    options.simplify = false;
    const PlanResult a = make_planner("rrtconnect")->plan(space, q.start, q.goal, options);
    options.simplify = true;
    const PlanResult b = make_planner("rrtconnect")->plan(space, q.start, q.goal, options);
    ASSERT_TRUE(a.success() && b.success()) << a.detail << " / " << b.detail;
    EXPECT_TRUE(path_clear_of_obstacles(office(), b.path, kRadius));
    raw += a.length_m;
    simplified += b.length_m;
  }
  EXPECT_LT(simplified, 0.9 * raw);
}

}  // namespace
}  // namespace fleetmap::planning
