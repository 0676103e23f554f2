#include "mapping/polynomial_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace fleetmap::mapping {
namespace {

Polynomial flat(double height, double lo, double hi, PolynomialAxis axis = PolynomialAxis::X1) {
  return {axis, {0.0, 0.0, 0.0}, height, lo, hi};
}

TEST(PolynomialMapGeometry, BestApproximationAndDensestCluster) {
  PolynomialMap map;
  map.landmarks.push_back({0, flat(1.0, 0.0, 2.0), {}, -1});
  map.landmarks.push_back({1, flat(3.0, 0.0, 2.0), {}, -1});
  const auto best = map.best_approximation({1.0, 2.8});
  EXPECT_EQ(best.index, 1);
  EXPECT_NEAR(best.error, 0.2, 1e-12);
  EXPECT_EQ(map.index_of(1), 1);
  EXPECT_EQ(map.index_of(7), -1);
  EXPECT_EQ(map.densest_cluster({5.0, 5.0}, 0.35), -1);
  map.clusters.push_back({{MapPoint{{5.0, 5.0}}}});
  map.clusters.push_back({{MapPoint{{5.2, 5.0}}, MapPoint{{5.3, 5.1}}}});
  EXPECT_EQ(map.densest_cluster({5.1, 5.0}, 0.35), 1);
  EXPECT_EQ(map.densest_cluster({4.8, 5.0}, 0.35), 0);
}

TEST(PolynomialMapGeometry, OverlapOfFig3) {
  const Polynomial a = flat(1.0, 0.0, 2.0);
  // (b) a common region.
  const auto ab = overlap(a, flat(1.05, 1.5, 3.0));
  ASSERT_TRUE(ab.has_value());
  EXPECT_NEAR(ab->lo, 1.5, 0.05);
  EXPECT_NEAR(ab->hi, 2.0, 1e-12);
  EXPECT_NEAR(ab->length, ab->hi - ab->lo, 1e-12);
  // (a) one inside the other.
  const auto inside = overlap(a, flat(1.0, -1.0, 5.0));
  ASSERT_TRUE(inside.has_value());
  EXPECT_NEAR(inside->length, 2.0, 1e-12);
  EXPECT_FALSE(overlap(a, flat(1.0, 2.5, 3.0)).has_value());
  // A perpendicular polynomial crossing a's region: the overlap is where a's points fall in its domain.
  const auto cross = overlap(a, flat(1.0, 0.5, 1.5, PolynomialAxis::X2));  // x1 = 1 for x2 in [0.5, 1.5]
  ASSERT_TRUE(cross.has_value());
  EXPECT_NEAR(tangent_angle(a, 1.0, flat(1.0, 0.5, 1.5, PolynomialAxis::X2)), std::numbers::pi / 2, 1e-9);
  EXPECT_NEAR(tangent_angle(a, 1.0, flat(5.0, 0.0, 2.0)), 0.0, 1e-9);
  EXPECT_NEAR(rms_residual(flat(1.1, 0.0, 2.0), {{0.0, 1.0}, {1.0, 1.0}}), 0.1, 1e-12);
}

TEST(PolynomialMapGeometry, MappingErrorNuAsDAlfonsoDefinesIt) {
  const std::vector<WallSegment> walls = {{{0.0, 0.0}, {4.0, 0.0}}, {{4.0, 0.0}, {4.0, 3.0}}};
  // On the wall: no error.
  const MappingError exact = mapping_error({flat(0.0, 0.5, 3.5)}, core::Transform2(), walls, 0.01);
  EXPECT_NEAR(exact.nu, 0.0, 1e-12);
  EXPECT_EQ(exact.samples, 301);
  // Two polynomials 2 cm off the wall: nu sums each one's deltas, then averages over polynomials.
  const MappingError off = mapping_error({flat(0.02, 0.5, 1.5), flat(0.02, 2.0, 3.0)}, core::Transform2(), walls, 0.01);
  EXPECT_EQ(off.polynomials, 2);
  EXPECT_EQ(off.samples, 202);
  EXPECT_NEAR(off.nu, 101 * 0.02, 1e-9);
  EXPECT_NEAR(off.mean_distance, 0.02, 1e-12);
  // The frame: a polynomial in a robot frame turned by 90 degrees lands on the second wall.
  const core::Transform2 frame(4.0, 0.0, std::numbers::pi / 2);  // robot frame x axis = world y axis
  EXPECT_NEAR(mapping_error({flat(0.0, 0.5, 2.5)}, frame, walls).mean_distance, 0.0, 1e-9);
}

TEST(PolynomialMapGeometry, BoundaryCoverage) {
  const std::vector<WallSegment> walls = {{{0.0, 0.0}, {4.0, 0.0}}};
  EXPECT_NEAR(boundary_coverage({flat(0.0, 0.0, 4.0)}, core::Transform2(), walls, 0.1, 0.02), 1.0, 1e-12);
  EXPECT_NEAR(boundary_coverage({flat(0.05, 0.0, 2.0)}, core::Transform2(), walls, 0.1, 0.02), 0.525, 0.01);
  EXPECT_NEAR(boundary_coverage({flat(0.5, 0.0, 4.0)}, core::Transform2(), walls, 0.1, 0.02), 0.0, 1e-12);
  EXPECT_EQ(boundary_coverage({}, core::Transform2(), walls), 0.0);
}

}  // namespace
}  // namespace fleetmap::mapping
