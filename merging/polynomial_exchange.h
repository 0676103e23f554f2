#pragma once
// D'Alfonso et al. §3.2: what two robots exchange at a rendezvous, and how the receiver brings it into its
// own frame. The sender r_l sends the polynomials it extracted since its last rendezvous with the
// receiver r_j (Remark 1) with its pose estimate; r_j cuts each polynomial into segments (a rotated
// polynomial is no polynomial), moves their end points with T_l0,j0 = T_j,j0 T_l,j T_l,l0^-1
// (rendezvous_transform_matrices) and hands them to its filter as curves to merge (§3.3).
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "core/transform2.h"
#include "localization/polynomial_slam.h"
#include "mapping/polynomial.h"

namespace fleetmap::merging {

struct PolynomialMessage {
  core::Pose2 sender_pose;                                   // x_l,k|k in R_l,0: T_l,l0
  Eigen::Matrix3d sender_covariance = Eigen::Matrix3d::Zero();
  double distance = 0.0;                                     // d_l,j as the sender measured it
  double bearing_sender_to_receiver = 0.0;                   // alpha_l,j, rad, in the sender's frame
  std::vector<mapping::Polynomial> polynomials;              // in R_l,0
  std::vector<double> position_variances;                    // Var(c_0) of each
};

// Bytes on the wire, every number a float64 (as the paper's Matlab doubles): a header of 64 bytes
// (pose 24, the pose covariance's x, y and theta variances 24, distance 8, bearing 8) plus a
// 4-byte polynomial count, and per polynomial 1 byte of axis, m + 1 coefficients, the domain's two
// ends and Var(c_0): 57 bytes for m = 3.
std::int64_t message_bytes(const PolynomialMessage& message);

// The occupancy-grid patch that would carry the same part of the map: every cell of the
// axis-aligned bounding box of the polynomials (sampled every `resolution`) at `resolution` metres
// per cell, one byte each, plus 16 bytes of origin and size. 0 for no polynomial.
std::int64_t grid_patch_bytes(const std::vector<mapping::Polynomial>& polynomials, double resolution);

struct ExchangeOptions {
  double segment_tolerance = 0.005;  // m: the piecewise-linear approximation's largest error
  double range_noise = 0.02;         // m, the camera's distance noise (standard deviation)
  double bearing_noise = 0.0175;     // rad, the camera's bearing noise
};

// The receiver's side. `receiver_pose` is x_j,k|k in R_j,0 (T_j,j0); `distance` and
// `bearing_receiver_to_sender` (alpha_j,l) are what the receiver measured. Each polynomial becomes
// a polyline in R_j,0 whose variance adds, for its points' common displacement, the relative pose's
// noise (distance, both bearings), the sender's pose covariance and Var(c_0); the receiver's own
// pose uncertainty enters through its filter (the transform depends on its pose).
std::vector<localization::ReceivedCurve> receive_polynomials(const PolynomialMessage& message,
                                                             const core::Pose2& receiver_pose, double distance,
                                                             double bearing_receiver_to_sender, int sender,
                                                             const ExchangeOptions& options);

}  // namespace fleetmap::merging
