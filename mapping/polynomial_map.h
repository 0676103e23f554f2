#pragma once
// A polynomial map (D'Alfonso et al., §3.1): the landmark set E (polynomials, each with its set Q_bad of
// badly approximated points), the clusters Z of points not mapped yet, the geometry of Fig. 3
// (how two polynomials overlap) and the mapping metrics of §4 against a true boundary.
// The map holds data; the filter that moves the c_0 coefficients is localization/polynomial_slam.
#include <Eigen/Core>

#include <limits>
#include <optional>
#include <vector>

#include "core/transform2.h"
#include "mapping/polynomial.h"

namespace fleetmap::mapping {

// A point pi_k^i of eq. (3) kept for a later fit, with what the landmark generation function's
// Jacobians (eq. (5)) need to know of its origin.
struct MapPoint {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double weight = 1.0;                                  // 1 / ||P_k|k-1|| (D'Alfonso et al., §3.3)
  Eigen::Vector2d observer = Eigen::Vector2d::Zero();   // the predicted robot position it was computed from
  Eigen::Vector2d beam = Eigen::Vector2d::UnitX();      // unit vector of the sensor axis
  long step = 0;
};

struct PointCluster {
  std::vector<MapPoint> points;  // oldest first
};

struct PolynomialLandmark {
  long id = 0;  // unique within its map; a refitted or merged landmark is a new one with a new id
  Polynomial polynomial;
  std::vector<MapPoint> bad_points;  // Q_bad(p)
  int received_from = -1;            // the robot whose curve it was made of (unchanged since); -1: own
  // How uncertain the shape is, beyond c_0: its position along the independent axis (m^2) and its
  // orientation about the domain's middle (rad^2), as when it was made.
  double along_variance = 0.0;
  double angle_variance = 0.0;
};

struct PolynomialMap {
  std::vector<PolynomialLandmark> landmarks;  // E
  std::vector<PointCluster> clusters;         // Z

  std::vector<Polynomial> polynomials() const;
  int index_of(long id) const;  // -1 when no landmark has that id

  // The landmark best approximating `point` (smallest approximation_error, Fig. 2).
  struct Best {
    int index = -1;
    double error = std::numeric_limits<double>::infinity();
  };
  Best best_approximation(const Eigen::Vector2d& point) const;

  // The cluster holding the most points within `radius` of `point` (the first on ties), or -1
  // when no cluster has a point that close (§3.1).
  int densest_cluster(const Eigen::Vector2d& point, double radius) const;
};

// The part of `a` that lies in the region `b` approximates (Fig. 3): the sub-interval of a's
// independent variable whose points have b's independent coordinate inside b's domain, found on
// 65 samples of a and taken as one interval; nullopt when there is none.
struct Overlap {
  double lo = 0.0, hi = 0.0;  // in a's independent variable
  double length = 0.0;        // arc length of a over [lo, hi]
};
std::optional<Overlap> overlap(const Polynomial& a, const Polynomial& b);

// The angle (radians, in [0, pi/2]) between the tangents of a and b at a's point a_xi.
double tangent_angle(const Polynomial& a, double a_xi, const Polynomial& b);

// D'Alfonso et al. §3.3's gamma: the LMS approximation error of `points` by b, as the RMS of the
// residuals eta - b(xi) in metres (so that it compares with gamma_M, given in metres).
double rms_residual(const Polynomial& b, const std::vector<Eigen::Vector2d>& points);

// A straight piece of the true environment boundary.
struct WallSegment {
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
};
double distance_to_walls(const Eigen::Vector2d& point, const std::vector<WallSegment>& walls);

// D'Alfonso et al. §4's nu: each polynomial sampled every `step` metres of curvilinear abscissa, its
// samples brought into the walls' frame by `to_truth`, delta = the distance of each to the nearest
// true boundary point; nu = (1/n) sum_q sum_i delta_q^i, as printed (a sum over each polynomial's
// samples, averaged over the polynomials). mean_distance is the plain mean of all deltas.
struct MappingError {
  double nu = 0.0;             // metres; 0 for an empty map
  double mean_distance = 0.0;  // metres
  double max_distance = 0.0;
  long samples = 0;
  int polynomials = 0;
};
MappingError mapping_error(const std::vector<Polynomial>& polynomials, const core::Transform2& to_truth,
                           const std::vector<WallSegment>& walls, double step = 0.01);

// The share of the true boundary (sampled every `step` metres) that lies within `tolerance`
// metres of a mapped polynomial (brought into the walls' frame by `to_truth`).
double boundary_coverage(const std::vector<Polynomial>& polynomials, const core::Transform2& to_truth,
                         const std::vector<WallSegment>& walls, double tolerance = 0.1, double step = 0.02);

}  // namespace fleetmap::mapping
