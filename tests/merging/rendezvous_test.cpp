#include "merging/rendezvous.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/angle.h"
#include "core/error.h"
#include "core/random.h"

namespace fleetmap::merging {
namespace {

// Ground truth of a meeting: both robots' true poses in the world and their map frames' poses.
struct Meeting {
  core::Transform2 self_map, other_map;  // map frames in the world
  core::Pose2 self_world, other_world;   // robots in the world
  core::Pose2 self_pose() const { return core::Pose2::from_transform(self_map.inverse() * self_world.as_transform()); }
  core::Pose2 other_pose() const { return core::Pose2::from_transform(other_map.inverse() * other_world.as_transform()); }
  core::Transform2 truth() const { return self_map.inverse() * other_map; }  // other's map into self's
  // What the robots measure of each other (exact).
  MutualObservation observe() const {
    const Eigen::Vector2d d = other_world.position() - self_world.position();
    MutualObservation z;
    z.range_self_to_other = z.range_other_to_self = d.norm();
    z.bearing_self_to_other = core::normalize_angle(std::atan2(d.y(), d.x()) - self_world.theta);
    z.bearing_other_to_self = core::normalize_angle(std::atan2(-d.y(), -d.x()) - other_world.theta);
    return z;
  }
};

Meeting random_meeting(core::Random& r) {
  const auto pose = [&](double span) { return core::Pose2(r.uniform(-span, span), r.uniform(-span, span), r.uniform(-3.1, 3.1)); };
  Meeting m;
  m.self_map = pose(50).as_transform();
  m.other_map = pose(50).as_transform();
  m.self_world = pose(20);
  const double bearing = r.uniform(-3.1, 3.1), range = r.uniform(0.5, 5.0);
  m.other_world = core::Pose2(m.self_world.x + range * std::cos(bearing), m.self_world.y + range * std::sin(bearing),
                              r.uniform(-3.1, 3.1));
  return m;
}

TEST(Rendezvous, MapAlignmentPaperEquations7To9RecoverTheMapTransform) {
  core::Random random(3);
  for (int i = 0; i < 100; ++i) {
    const Meeting m = random_meeting(random);
    const core::Transform2 t = rendezvous_transform(m.self_pose(), m.other_pose(), m.observe());
    EXPECT_TRUE(t.is_approx(m.truth(), 1e-9)) << t << " vs " << m.truth();
  }
}

TEST(Rendezvous, DAlfonsoMatrixProductAgrees) {
  core::Random random(4);
  for (int i = 0; i < 100; ++i) {
    const Meeting m = random_meeting(random);
    const MutualObservation z = m.observe();
    const core::Transform2 t = rendezvous_transform_matrices(m.self_pose(), m.other_pose(), z.range_self_to_other,
                                                             z.bearing_self_to_other, z.bearing_other_to_self);
    EXPECT_TRUE(t.is_approx(m.truth(), 1e-9)) << t << " vs " << m.truth();
  }
}

TEST(Rendezvous, RangesAreAveraged) {
  core::Random random(5);
  const Meeting m = random_meeting(random);
  MutualObservation z = m.observe();
  const double true_range = z.range_self_to_other;
  z.range_self_to_other = true_range + 0.2;
  z.range_other_to_self = true_range - 0.2;
  EXPECT_TRUE(rendezvous_transform(m.self_pose(), m.other_pose(), z).is_approx(m.truth(), 1e-9));
}

TEST(Rendezvous, HandComputedCase) {
  // Both at their map origins facing +x, the other 2 m ahead, facing back: its map is turned by pi
  // and its origin lies at (2, 0) in self's map.
  MutualObservation z{2.0, 0.0, 2.0, 0.0};
  const core::Transform2 t = rendezvous_transform({0, 0, 0}, {0, 0, 0}, z);
  EXPECT_TRUE(t.is_approx(core::Transform2(2.0, 0.0, std::numbers::pi), 1e-12)) << t;
}

TEST(GridTransforms, CellsAndWorldRoundTrip) {
  const core::GridGeometry a(0.05, 100, 80, core::Pose2(-2.0, 1.0, 0.3));
  const core::GridGeometry b(0.05, 60, 90, core::Pose2(4.0, -3.0, -1.2));
  const core::Transform2 world(0.7, -0.4, 0.9);
  const core::Transform2 cells = cells_from_world(a, b, world);
  // Cell centres map as the world points do.
  for (const core::Cell c : {core::Cell{0, 0}, core::Cell{59, 0}, core::Cell{17, 42}}) {
    const Eigen::Vector2d w = world.apply(b.cell_center(c));
    const Eigen::Vector2d g = a.world_to_grid(w) - Eigen::Vector2d(0.5, 0.5);
    EXPECT_TRUE(cells.apply(Eigen::Vector2d(c.x, c.y)).isApprox(g, 1e-9));
  }
  EXPECT_TRUE(world_from_cells(a, b, cells).is_approx(world, 1e-9));
  EXPECT_THROW(cells_from_world(a, core::GridGeometry(0.1, 10, 10), world), Error);
}

TEST(GridTransforms, FlipRowsIsTheImageConventionAndItsOwnInverse) {
  // b is a copy of a: in cells and in pixels the transform is the identity.
  EXPECT_TRUE(flip_rows(core::Transform2::identity(), 50, 50).is_approx(core::Transform2::identity(), 1e-12));
  // A cell transform turning b by +90 degrees about a's origin is -90 degrees in image pixels.
  const core::Transform2 cells(10.0, 5.0, std::numbers::pi / 2);
  const core::Transform2 pixels = flip_rows(cells, 40, 30);
  EXPECT_NEAR(pixels.rotation(), -std::numbers::pi / 2, 1e-12);
  // Pixel (u, v) of b is cell (u, 29 - v); check one point through both routes.
  const Eigen::Vector2d uv(7.0, 3.0);
  const Eigen::Vector2d cell_a = cells.apply(Eigen::Vector2d(uv.x(), 29.0 - uv.y()));
  const Eigen::Vector2d pixel_a(cell_a.x(), 39.0 - cell_a.y());
  EXPECT_TRUE(pixels.apply(uv).isApprox(pixel_a, 1e-12));
  EXPECT_TRUE(flip_rows(pixels, 40, 30).is_approx(cells, 1e-12));
}

}  // namespace
}  // namespace fleetmap::merging
