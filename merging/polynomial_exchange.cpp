#include "merging/polynomial_exchange.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "merging/rendezvous.h"

namespace fleetmap::merging {

std::int64_t message_bytes(const PolynomialMessage& m) {
  constexpr std::int64_t kHeader = 24 + 24 + 8 + 8 + 4;
  std::int64_t bytes = kHeader;
  for (const auto& p : m.polynomials) bytes += 1 + 8 * (p.order() + 1) + 2 * 8 + 8;
  return bytes;
}

std::int64_t grid_patch_bytes(const std::vector<mapping::Polynomial>& polynomials, double resolution) {
  if (polynomials.empty() || !(resolution > 0.0)) return 0;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const auto& p : polynomials) {
    for (const auto& q : mapping::sample_arc_length(p, resolution)) {
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  }
  const auto cells = [&](double extent) { return std::int64_t(std::floor(extent / resolution)) + 1; };
  return cells(hi.x() - lo.x()) * cells(hi.y() - lo.y()) + 16;
}

std::vector<localization::ReceivedCurve> receive_polynomials(const PolynomialMessage& m,
                                                             const core::Pose2& receiver_pose, double distance,
                                                             double bearing_receiver_to_sender, int sender,
                                                             const ExchangeOptions& options) {
  // D'Alfonso et al. §3.2 with both robots' distance readings averaged.
  const double d = 0.5 * (distance + m.distance);
  const core::Transform2 t = rendezvous_transform_matrices(receiver_pose, m.sender_pose, d, bearing_receiver_to_sender,
                                                           m.bearing_sender_to_receiver);
  // Uncertainty of a point at lever arm a from the sender, in the receiver's robot frame:
  // the sender's position in it (distance noise / 2 for the average, d x bearing noise), the
  // relative heading vartheta = pi + alpha_j,l - alpha_l,j (two bearings) and the sender's own
  // heading, both turning the lever arm, and the sender's position uncertainty.
  const double s_r = options.range_noise, s_b = options.bearing_noise;
  const double base = 0.5 * s_r * s_r + d * d * s_b * s_b +
                      0.5 * (m.sender_covariance(0, 0) + m.sender_covariance(1, 1));
  const double heading_var = 2.0 * s_b * s_b + m.sender_covariance(2, 2);
  std::vector<localization::ReceivedCurve> out;
  for (std::size_t i = 0; i < m.polynomials.size(); ++i) {
    const std::vector<Eigen::Vector2d> vertices = mapping::segment_polynomial(m.polynomials[i], options.segment_tolerance);
    localization::ReceivedCurve c;
    c.from_robot = sender;
    double lever2 = 0.0;
    for (const auto& v : vertices) {
      c.polyline.push_back(t * v);
      lever2 += (v - m.sender_pose.position()).squaredNorm();
    }
    lever2 /= double(std::max<std::size_t>(1, vertices.size()));
    const double c0_var = i < m.position_variances.size() ? m.position_variances[i] : 0.0;
    c.variance = base + lever2 * heading_var + c0_var;
    c.angle_variance = heading_var;
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace fleetmap::merging
