#include "localization/submap_matching.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace fleetmap::localization {
namespace {

// The walls of a room open at the bottom, 2 m wide and 2 m deep, as points every 5 cm about
// `origin`: the top wall, the two side walls and a post inside.
PointCloud room(const Eigen::Vector2d& origin, bool with_sides) {
  PointCloud out;
  for (double t = -1.0; t <= 1.0 + 1e-9; t += 0.05) {
    out.push_back(origin + Eigen::Vector2d(t, 1.0));
    if (with_sides) {
      out.push_back(origin + Eigen::Vector2d(-1.0, t));
      out.push_back(origin + Eigen::Vector2d(1.0, t));
    }
  }
  for (double t = -0.2; t <= 0.2 + 1e-9; t += 0.05) out.push_back(origin + Eigen::Vector2d(0.4 + t, 0.3));
  return out;
}

// A submap holding the room at the origin and a second room 4 m to its right, each inserted as
// seen from its centre ten times (so their walls are sure).
SubmapGrid two_rooms(bool second_like_first) {
  SubmapGrid grid;
  for (int k = 0; k < 10; ++k) {
    grid.insert({0.0, 0.0}, room({0.0, 0.0}, true));
    grid.insert({4.0, 0.0}, room({4.0, 0.0}, second_like_first));
  }
  return grid;
}

// The rival check of a loop closure: the best match elsewhere in the window (farther than 1 m from
// the match found), when the scan's points prefer the match to it by fewer than two standard errors.
std::optional<MatchResult> rival_of(const SubmapGrid& grid, const PointCloud& scan, const core::Pose2& center,
                                    const MatchResult& match) {
  BranchAndBoundOptions o;
  o.exclude_center = match.pose.position();
  o.exclude_radius_m = 1.0;
  const auto rival = branch_and_bound_match(PrecomputedGrids(grid, 7), scan, center, o);
  if (rival && score_advantage(grid, scan, match.pose, rival->pose) < 2.0) return rival;
  return std::nullopt;
}

TEST(BranchAndBound, ARoomRepeatedElsewhereInTheWindowIsARivalOfTheMatch) {
  const SubmapGrid grid = two_rooms(true);
  const PointCloud scan = room({0.0, 0.0}, true);  // the sensor at a room's centre
  const core::Pose2 center(2.0, 0.0, 0.0);          // halfway: both rooms in the 7 m window
  const PrecomputedGrids grids(grid, 7);
  BranchAndBoundOptions o;
  o.min_score = 0.0;
  const auto match = branch_and_bound_match(grids, scan, center, o);
  ASSERT_TRUE(match);
  const double x = match->pose.x;
  EXPECT_TRUE(std::abs(x) < 0.1 || std::abs(x - 4.0) < 0.1) << match->pose;
  EXPECT_NEAR(match->pose.y, 0.0, 0.1);
  const auto rival = rival_of(grid, scan, center, *match);
  ASSERT_TRUE(rival) << "the other room is as good a match";
  EXPECT_NEAR(std::abs(rival->pose.x - x), 4.0, 0.1) << rival->pose;
  EXPECT_NEAR(rival->pose.y, 0.0, 0.1);
}

TEST(BranchAndBound, AMatchWithNoLikePlaceInTheWindowHasNoRival) {
  const SubmapGrid grid = two_rooms(false);  // the second room has no side walls
  const PointCloud scan = room({0.0, 0.0}, true);
  const core::Pose2 center(2.0, 0.0, 0.0);
  BranchAndBoundOptions o;
  o.min_score = 0.0;
  const auto match = branch_and_bound_match(PrecomputedGrids(grid, 7), scan, center, o);
  ASSERT_TRUE(match);
  EXPECT_NEAR(match->pose.x, 0.0, 0.1) << match->pose;
  EXPECT_NEAR(match->pose.y, 0.0, 0.1);
  EXPECT_FALSE(rival_of(grid, scan, center, *match));
}

TEST(BranchAndBound, ExcludedPosesAreNeverTheAnswer) {
  const SubmapGrid grid = two_rooms(false);
  const PointCloud scan = room({0.0, 0.0}, true);
  BranchAndBoundOptions o;
  o.min_score = 0.0;
  o.exclude_center = Eigen::Vector2d(0.0, 0.0);
  o.exclude_radius_m = 1.0;
  const auto found = branch_and_bound_match(PrecomputedGrids(grid, 7), scan, core::Pose2(2.0, 0.0, 0.0), o);
  ASSERT_TRUE(found);
  EXPECT_GT(found->pose.position().norm(), 1.0) << found->pose;
}

// A corridor 2 m wide along x, 20 m long (its walls through the middle of a row of cells), seen from
// its middle with its ends out of sight, each stretch by `scans` scans.
SubmapGrid corridor(int scans = 5) {
  SubmapGrid grid;
  for (double x0 = -8.0; x0 <= 8.0; x0 += 1.0) {
    PointCloud walls;
    for (double t = -3.0; t <= 3.0 + 1e-9; t += 0.05) walls.push_back({x0 + t, 1.025}), walls.push_back({x0 + t, -1.025});
    for (int k = 0; k < scans; ++k) grid.insert({x0, 0.0}, walls);
  }
  return grid;
}

PointCloud corridor_scan() {
  PointCloud out;
  for (double t = -3.0; t <= 3.0 + 1e-9; t += 0.05) out.push_back({t, 1.025}), out.push_back({t, -1.025});
  return out;
}

TEST(ScoreCurvature, ACorridorsMatchIsFixedAcrossItAndFreeAlongIt) {
  const Eigen::Matrix2d a = score_curvature(corridor(), corridor_scan(), core::Pose2(0.0, 0.0, 0.0), 0.025);
  EXPECT_GT(a(1, 1), 0.0);
  EXPECT_LT(a(0, 0), 0.05 * a(1, 1)) << a;
}

TEST(RefineMatch, TheScanFixesTheCorridorsWidthAndThePredictionItsLength) {
  const SubmapGrid grid = corridor();
  // The prediction is 0.3 m along and 4 cm across from the truth (the origin).
  const core::Pose2 prediction(0.3, 0.02, 0.0);
  RefineOptions o;
  o.fixed_translation_weight = 1.0;
  const core::Pose2 refined = refine_match(grid, corridor_scan(), prediction, prediction, o);
  EXPECT_NEAR(refined.y, 0.0, 0.015) << refined;  // the walls decide across (a third of a cell)
  EXPECT_NEAR(refined.x, 0.3, 0.02) << refined;   // nothing along: the prediction holds
}

// As above on a corridor seen once, fitting its surface field: the walls decide across, the
// prediction along. The field (sigma 2.9 cm) is narrower than the probabilities' blur, so the fit
// starts within half a cell across, where the correlative search leaves it (from 4 cm off it
// reaches 1.6 cm).
TEST(RefineMatch, TheSurfaceFieldFixesTheCorridorsWidthAndThePredictionItsLength) {
  SubmapGridOptions go;
  go.hit_field_sigma_m = 0.0286;
  SubmapGrid grid(go);
  for (double x0 = -8.0; x0 <= 8.0; x0 += 1.0) {
    PointCloud walls;
    for (double t = -3.0; t <= 3.0 + 1e-9; t += 0.05) walls.push_back({x0 + t, 1.025}), walls.push_back({x0 + t, -1.025});
    grid.insert({x0, 0.0}, walls);
    for (std::size_t i = 2; i < walls.size(); ++i) grid.add_surface(walls[i - 2], walls[i]);
  }
  const core::Pose2 prediction(0.3, 0.02, 0.0);
  RefineOptions o;
  o.fixed_translation_weight = 1.0;
  o.hit_field = true;
  const core::Pose2 refined = refine_match(grid, corridor_scan(), prediction, prediction, o);
  EXPECT_NEAR(refined.y, 0.0, 0.015) << refined;
  EXPECT_NEAR(refined.x, 0.3, 0.02) << refined;
}

TEST(RefineMatch, TheSearchsAnswerHoldsAlongADeadEndCorridor) {
  // A corridor 2 m wide closed 2 m ahead, seen once (walls 0.55 against 0.49 for free cells): its
  // end wall fixes the position along it, less surely than the side walls across.
  PointCloud scan;
  for (double t = -3.0; t <= 2.0 + 1e-9; t += 0.05) scan.push_back({t, 1.025}), scan.push_back({t, -1.025});
  for (double t = -1.0; t <= 1.0 + 1e-9; t += 0.05) scan.push_back({2.025, t});
  SubmapGrid grid;
  grid.insert({0.0, 0.0}, scan);
  // The search found the truth (the origin); the prediction is 10 cm short of the end wall.
  const core::Pose2 found(0.0, 0.0, 0.0), prediction(-0.1, 0.0, 0.0);
  RefineOptions o;
  o.fixed_translation_weight = 1.0;
  const core::Pose2 refined = refine_match(grid, scan, found, prediction, o);
  // The end wall moves the answer off the prediction by more than half a cell (the pull toward the
  // prediction alone leaves it within a few millimetres of it), the side walls hold it across.
  EXPECT_GT(refined.x, prediction.x + 0.5 * grid.resolution()) << refined;
  EXPECT_NEAR(refined.y, 0.0, 0.25 * grid.resolution()) << refined;
}

// Every pose of the window around `center` (the search's angles and offsets), scored as the search
// scores a pose: the best score there is the one the search must return.
double exhaustive_best(const PrecomputedGrids& grids, const PointCloud& points, const core::Pose2& center,
                       const BranchAndBoundOptions& o) {
  const double r = grids.resolution();
  const int w = int(std::ceil(o.linear_window_m / r));
  const double step = angular_search_step(points, r);
  const int na = int(std::ceil(o.angular_window_rad / step));
  double best = -1.0;
  for (int k = -na; k <= na; ++k) {
    const double da = k * step;
    const double c = std::cos(center.theta + da), s = std::sin(center.theta + da);
    std::vector<Eigen::Vector2i> cells;
    for (const auto& p : points) {
      cells.emplace_back(int(std::floor((c * p.x() - s * p.y() + center.x) / r)), int(std::floor((s * p.x() + c * p.y() + center.y) / r)));
    }
    for (int dy = -w; dy <= w; ++dy) {
      for (int dx = -w; dx <= w; ++dx) {
        int sum = 0;
        for (const auto& cell : cells) sum += grids.value(0, cell.x() + dx, cell.y() + dy);
        const double penalty = std::hypot(dx * r, dy * r) * o.translation_weight + std::abs(da) * o.rotation_weight;
        best = std::max(best, double(sum) / (double(points.size()) * 255.0) * std::exp(-penalty * penalty));
      }
    }
  }
  return best;
}

TEST(BranchAndBound, FindsTheBestScoreOfTheExhaustiveSearch) {
  const SubmapGrid grid = two_rooms(false);
  // The room's scan seen from off its centre and turned, so that its best pose is not the window's
  // centre, with returns from beyond its top wall, where the submap knows nothing (off its cells).
  PointCloud scan;
  const core::Pose2 truth(0.3, -0.15, 0.08);
  PointCloud seen = room({0.0, 0.0}, true);
  for (double t = -1.0; t <= 1.0 + 1e-9; t += 0.2) seen.push_back({t, 3.0});
  for (const auto& p : seen) scan.push_back(truth.inverse().transform(p));
  const core::Pose2 center(0.1, 0.1, 0.0);
  for (const int depth : {3, 7}) {
    const PrecomputedGrids grids(grid, depth);
    for (const double weight : {0.0, 1.0}) {
      BranchAndBoundOptions o;
      o.linear_window_m = 1.0;
      o.angular_window_rad = 0.2;
      o.min_score = 0.0;
      o.translation_weight = weight;
      o.rotation_weight = weight;
      const auto match = branch_and_bound_match(grids, scan, center, o);
      ASSERT_TRUE(match);
      EXPECT_DOUBLE_EQ(match->score, exhaustive_best(grids, scan, center, o)) << "depth " << depth << ", weight " << weight;
      EXPECT_NEAR(match->pose.x, truth.x, 0.1) << match->pose;
      EXPECT_NEAR(match->pose.y, truth.y, 0.1) << match->pose;
    }
  }
}

TEST(SubmapGrid, AGridThatReleasedItsInsertionStateTakesScansAsBefore) {
  SubmapGrid kept, released;
  for (int k = 0; k < 3; ++k) {
    kept.insert({0.0, 0.0}, room({0.0, 0.0}, true));
    released.insert({0.0, 0.0}, room({0.0, 0.0}, true));
  }
  released.release_insertion_state();
  // More scans, one of them beyond the grid's bounds (the grid grows).
  for (int k = 0; k < 3; ++k) {
    for (SubmapGrid* g : {&kept, &released}) {
      g->insert({0.2, 0.1}, room({0.0, 0.0}, true));
      g->insert({6.0, 0.0}, room({6.0, 0.0}, true));
    }
  }
  ASSERT_EQ(released.min_x(), kept.min_x());
  ASSERT_EQ(released.min_y(), kept.min_y());
  ASSERT_EQ(released.width(), kept.width());
  ASSERT_EQ(released.height(), kept.height());
  EXPECT_EQ(released.known_cells(), kept.known_cells());
  for (int y = kept.min_y(); y < kept.min_y() + kept.height(); ++y) {
    for (int x = kept.min_x(); x < kept.min_x() + kept.width(); ++x) ASSERT_EQ(released.probability(x, y), kept.probability(x, y)) << x << " " << y;
  }
}

// The surface field of a wall seen once: 1 on the wall (where the probabilities read 0.55), 0 in
// the free space before it (0.49) and in unknown space (0.1); a segment between two returns
// raises the cells between them; the field survives the grid's growth.
TEST(SubmapGrid, TheSurfaceFieldOfAWallSeenOnceStandsOutOfFreeAndUnknownSpace) {
  SubmapGridOptions o;
  const double r = o.resolution_m;
  const double range_noise = 0.02;
  o.hit_field_sigma_m = std::sqrt(range_noise * range_noise + 2.0 * r * r / 12.0);
  SubmapGrid grid(o);
  PointCloud wall;
  for (double t = -1.0; t <= 1.0 + 1e-9; t += 0.4) wall.push_back({2.025, t});  // dots 8 cells apart
  grid.insert({0.0, 0.0}, wall);
  for (std::size_t i = 1; i < wall.size(); ++i) grid.add_surface(wall[i - 1], wall[i]);
  const Eigen::Vector2i on = grid.cell_of({2.025, 0.2}), between = grid.cell_of({2.025, 0.0});
  const Eigen::Vector2i free = grid.cell_of({1.0125, 0.1}), unknown = grid.cell_of({3.0, 0.0});
  EXPECT_FLOAT_EQ(grid.hit_field(on.x(), on.y()), 1.0f);
  EXPECT_FLOAT_EQ(grid.hit_field(between.x(), between.y()), 1.0f);  // on the segment, no return there
  EXPECT_FLOAT_EQ(grid.hit_field(free.x(), free.y()), 0.0f);
  EXPECT_FLOAT_EQ(grid.hit_field(unknown.x(), unknown.y()), 0.0f);
  // A cell beside the wall reads the Gaussian of a cell's distance.
  const float beside = grid.hit_field(on.x() - 1, on.y());
  EXPECT_NEAR(beside, std::exp(-0.5 * r * r / (o.hit_field_sigma_m * o.hit_field_sigma_m)), 1e-6);
  EXPECT_GT(grid.probability(on.x(), on.y()), 0.5f);
  EXPECT_GT(grid.probability(free.x(), free.y()), 0.45f);  // the probabilities barely tell them apart
  // Growing the grid (a scan far away) keeps the field.
  grid.insert({10.0, 0.0}, {{12.0, 0.0}});
  const Eigen::Vector2i moved = grid.cell_of({2.025, 0.2});
  EXPECT_FLOAT_EQ(grid.hit_field(moved.x(), moved.y()), 1.0f);
  grid.release_insertion_state();
  EXPECT_FLOAT_EQ(grid.hit_field(moved.x(), moved.y()), 0.0f);
}

// The local search by the surface field finds a room seen once (its walls in the middle of
// cells) from a prior off by two cells and one.
TEST(Correlative, TheSurfaceFieldFindsARoomSeenOnce) {
  SubmapGridOptions o;
  o.hit_field_sigma_m = 0.0286;
  SubmapGrid grid(o);
  const core::Pose2 truth(0.025, 0.025, 0.0), prior(0.125, -0.025, 0.0);
  const PointCloud scan = room({0.0, 0.0}, true);
  PointCloud walls;
  for (const auto& p : scan) walls.push_back(truth.transform(p));
  grid.insert(truth.position(), walls);
  for (const auto& p : walls) grid.add_surface(p, p);
  CorrelativeOptions c;
  c.hit_field = true;
  const MatchResult m = correlative_match(grid, scan, prior, c);
  EXPECT_NEAR(m.pose.x, truth.x, 0.5 * o.resolution_m) << m.pose;
  EXPECT_NEAR(m.pose.y, truth.y, 0.5 * o.resolution_m) << m.pose;
  EXPECT_NEAR(m.pose.theta, truth.theta, 0.01) << m.pose;
  EXPECT_GT(m.score, 0.9);
}

}  // namespace
}  // namespace fleetmap::localization
