#include "mapping/ray_cast.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace fleetmap::mapping {
namespace {

// A room of w x h cells of 0.1 m whose outermost ring of cells is wall; inside is free.
OccupancyGrid room(int w, int h) {
  OccupancyGrid g(GridGeometry(0.1, w, h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      g.set_state({x, y}, (x == 0 || y == 0 || x == w - 1 || y == h - 1) ? CellState::Occupied : CellState::Free);
  return g;
}

TEST(RayCast, ExactDistanceToWalls) {
  const auto g = room(20, 10);  // inner free box: x in [0.1, 1.9], y in [0.1, 0.9]
  EXPECT_NEAR(*cast_ray(g, {0.55, 0.45}, 0.0, 10.0), 1.9 - 0.55, 1e-9);
  EXPECT_NEAR(*cast_ray(g, {0.55, 0.45}, std::numbers::pi, 10.0), 0.55 - 0.1, 1e-9);
  EXPECT_NEAR(*cast_ray(g, {0.55, 0.45}, std::numbers::pi / 2, 10.0), 0.9 - 0.45, 1e-9);
  EXPECT_FALSE(cast_ray(g, {0.55, 0.45}, 0.0, 1.0).has_value());  // wall beyond max range
}

TEST(RayCast, MatchesGeometryForRandomRays) {
  const int w = 60, h = 40;
  const auto g = room(w, h);
  const double lo_x = 0.1, hi_x = (w - 1) * 0.1, lo_y = 0.1, hi_y = (h - 1) * 0.1;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> px(lo_x + 0.01, hi_x - 0.01), py(lo_y + 0.01, hi_y - 0.01),
      pa(-std::numbers::pi, std::numbers::pi);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector2d p(px(rng), py(rng));
    const double a = pa(rng), c = std::cos(a), s = std::sin(a);
    double expected = 1e9;
    if (c > 1e-12) expected = std::min(expected, (hi_x - p.x()) / c);
    if (c < -1e-12) expected = std::min(expected, (lo_x - p.x()) / c);
    if (s > 1e-12) expected = std::min(expected, (hi_y - p.y()) / s);
    if (s < -1e-12) expected = std::min(expected, (lo_y - p.y()) / s);
    const auto d = cast_ray(g, p, a, 100.0);
    ASSERT_TRUE(d.has_value());
    EXPECT_NEAR(*d, expected, 1e-9) << "from " << p.transpose() << " angle " << a;
  }
}

TEST(RayCast, UnknownCellsBlockByDefault) {
  OccupancyGrid g(GridGeometry(1.0, 10, 1));
  for (int x = 0; x < 5; ++x) g.set_state({x, 0}, CellState::Free);
  EXPECT_NEAR(*cast_ray(g, {0.5, 0.5}, 0.0, 20.0), 4.5, 1e-12);
  RayCastOptions see_through;
  see_through.unknown_blocks = false;
  EXPECT_FALSE(cast_ray(g, {0.5, 0.5}, 0.0, 20.0, see_through).has_value());
}

TEST(LineOfSight, BlockedByWallBetween) {
  auto g = room(20, 20);
  for (int y = 0; y < 15; ++y) g.set_state({10, y}, CellState::Occupied);
  EXPECT_FALSE(line_of_sight(g, {0.5, 0.5}, {1.5, 0.5}));
  EXPECT_TRUE(line_of_sight(g, {0.5, 1.7}, {1.5, 1.7}));
  EXPECT_TRUE(line_of_sight(g, {0.5, 0.5}, {0.5, 1.5}));
}

}  // namespace
}  // namespace fleetmap::mapping
