#include "merging/polynomial_exchange.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/angle.h"
#include "core/random.h"
#include "merging/rendezvous.h"

namespace fleetmap::merging {
namespace {

TEST(PolynomialExchange, TransformL0J0AgainstAHandComputedCase) {
  // r_j is at (1, 0, 0) in its frame R_j,0, r_l at (0, 0, pi/2) in R_l,0. r_j sees r_l 2 m straight
  // ahead (alpha_j,l = 0) and r_l faces it (alpha_l,j = 0), so vartheta = pi and
  // T_l0,j0 = T_j,j0 T_l,j T_l,l0^-1 = [R(0), (1, 0)] [R(pi), (2, 0)] [R(-pi/2), 0] = [R(pi/2), (3, 0)].
  const core::Transform2 t = rendezvous_transform_matrices({1.0, 0.0, 0.0}, {0.0, 0.0, std::numbers::pi / 2}, 2.0, 0.0, 0.0);
  EXPECT_TRUE(t.is_approx(core::Transform2(3.0, 0.0, std::numbers::pi / 2), 1e-12)) << t;
  // A point 1 m to r_l's right in R_l,0 is 1 m to r_l's right in R_j,0, where r_l faces -x1.
  EXPECT_TRUE((t * Eigen::Vector2d(1.0, 0.0)).isApprox(Eigen::Vector2d(3.0, 1.0), 1e-12));

  // The same through the exchange: the line x2 = 1, x1 in [0, 2] of R_l,0 arrives as x1 = 2, x2 in [0, 2].
  PolynomialMessage m;
  m.sender_pose = {0.0, 0.0, std::numbers::pi / 2};
  m.distance = 2.0;
  m.bearing_sender_to_receiver = 0.0;
  m.polynomials = {{mapping::PolynomialAxis::X1, {0.0, 0.0, 0.0}, 1.0, 0.0, 2.0}};
  m.position_variances = {1e-4};
  const auto curves = receive_polynomials(m, {1.0, 0.0, 0.0}, 2.0, 0.0, 1, {});
  ASSERT_EQ(curves.size(), 1u);
  EXPECT_EQ(curves[0].from_robot, 1);
  ASSERT_EQ(curves[0].polyline.size(), 2u);  // a straight line needs one segment
  EXPECT_TRUE(curves[0].polyline.front().isApprox(Eigen::Vector2d(2.0, 0.0), 1e-12));
  EXPECT_TRUE(curves[0].polyline.back().isApprox(Eigen::Vector2d(2.0, 2.0), 1e-12));
  EXPECT_GT(curves[0].variance, 1e-4);
}

TEST(PolynomialExchange, CurvesLandOnTheTrueWallsOfARandomMeeting) {
  // Two robots with their own map frames meet; a curve the sender mapped (the true wall expressed
  // in its frame) arrives on the same wall in the receiver's frame, within the segmentation tolerance.
  core::Random rng(9);
  for (int trial = 0; trial < 20; ++trial) {
    const core::Transform2 l_map(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-3, 3));
    const core::Transform2 j_map(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-3, 3));
    const core::Pose2 l_world(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-3, 3));
    const double bearing = rng.uniform(-3, 3), range = rng.uniform(0.5, 2.0);
    const core::Pose2 j_world(l_world.x + range * std::cos(bearing), l_world.y + range * std::sin(bearing), rng.uniform(-3, 3));
    const auto in_frame = [](const core::Transform2& frame, const core::Pose2& p) {
      return core::Pose2::from_transform(frame.inverse() * p.as_transform());
    };
    // A curved wall in the sender's frame.
    const mapping::Polynomial wall{mapping::PolynomialAxis::X1, {0.05, -0.2, 0.3}, 1.0, -1.0, 1.5};
    PolynomialMessage m;
    m.sender_pose = in_frame(l_map, l_world);
    m.distance = range;
    const Eigen::Vector2d d = j_world.position() - l_world.position();
    m.bearing_sender_to_receiver = core::normalize_angle(std::atan2(d.y(), d.x()) - l_world.theta);
    m.polynomials = {wall};
    m.position_variances = {0.0};
    const double bearing_j = core::normalize_angle(std::atan2(-d.y(), -d.x()) - j_world.theta);
    ExchangeOptions options;
    options.segment_tolerance = 0.002;
    const auto curves = receive_polynomials(m, in_frame(j_map, j_world), range, bearing_j, 0, options);
    ASSERT_EQ(curves.size(), 1u);
    const core::Transform2 l_to_j = j_map.inverse() * l_map;  // the truth
    for (double xi = wall.lo; xi <= wall.hi; xi += 0.01) {
      EXPECT_LE(mapping::distance_to_polyline(l_to_j * wall.point(xi), curves[0].polyline), 0.002 + 1e-9);
    }
  }
}

TEST(PolynomialExchange, BytesAgainstTheGridPatch) {
  PolynomialMessage m;
  EXPECT_EQ(message_bytes(m), 68);
  m.polynomials.assign(3, {mapping::PolynomialAxis::X1, {0.0, 0.0, 0.0}, 1.0, 0.0, 2.0});
  EXPECT_EQ(message_bytes(m), 68 + 3 * 57);  // m = 3: axis, 4 coefficients, domain, Var(c0)
  // A 2 m straight wall at 5 cm cells: 41 x 1 cells plus the patch header.
  EXPECT_NEAR(double(grid_patch_bytes({m.polynomials[0]}, 0.05)), 41.0 + 16.0, 1.0);
  // An L of two 2 m walls: the 2 x 2 m box.
  const std::vector<mapping::Polynomial> corner = {{mapping::PolynomialAxis::X1, {0.0, 0.0, 0.0}, 0.0, 0.0, 2.0},
                                                   {mapping::PolynomialAxis::X2, {0.0, 0.0, 0.0}, 0.0, 0.0, 2.0}};
  EXPECT_NEAR(double(grid_patch_bytes(corner, 0.05)), 41.0 * 41.0 + 16.0, 82.0);
  EXPECT_EQ(grid_patch_bytes({}, 0.05), 0);
}

TEST(PolynomialExchange, FartherCurvesAreLessCertain) {
  PolynomialMessage m;
  m.sender_pose = {0.0, 0.0, 0.0};
  m.distance = 1.0;
  m.polynomials = {{mapping::PolynomialAxis::X1, {0.0, 0.0, 0.0}, 1.0, 0.0, 1.0},
                   {mapping::PolynomialAxis::X1, {0.0, 0.0, 0.0}, 5.0, 0.0, 1.0}};
  m.position_variances = {1e-4, 1e-4};
  const auto curves = receive_polynomials(m, {0.0, 0.0, 0.0}, 1.0, 0.0, 1, {});
  ASSERT_EQ(curves.size(), 2u);
  EXPECT_GT(curves[1].variance, curves[0].variance);
  EXPECT_GT(curves[0].angle_variance, 0.0);
}

}  // namespace
}  // namespace fleetmap::merging
