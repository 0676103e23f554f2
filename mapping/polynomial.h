#pragma once
// Polynomial landmarks (D'Alfonso et al., §2, Fig. 1-2): an m-th order polynomial p(xi) = sum_i b_i xi^i + c_0
// over a domain [lo, hi] of its independent variable. An x1-variate polynomial is the curve
// x2 = p(x1); an x2-variate one is x1 = p(x2), so that steep walls are polynomials too (§3.1).
// The shape coefficients b_m..b_1 are the "shape landmark", c_0 the "innovation landmark" that an
// EKF moves: changing c_0 by d shifts the whole curve by d along its dependent axis.
// Everything here is geometry in one frame (metres); nothing knows of robots or filters.
#include <Eigen/Core>

#include <iosfwd>
#include <optional>
#include <vector>

namespace fleetmap::mapping {

enum class PolynomialAxis {
  X1,  // x1-variate: x2 = p(x1)
  X2,  // x2-variate: x1 = p(x2)
};

struct Polynomial {
  PolynomialAxis axis = PolynomialAxis::X1;
  std::vector<double> shape;  // b_m, b_{m-1}, ..., b_1 (highest power first, as the paper lists them)
  double position = 0.0;      // c_0
  double lo = 0.0;            // domain [lo, hi] of the independent variable; Q_m = point(lo), Q_M = point(hi)
  double hi = 0.0;

  int order() const { return static_cast<int>(shape.size()); }
  double value(double xi) const;  // p(xi), by Horner's rule
  double slope(double xi) const;  // p'(xi)
  // The curve point at xi, in (x1, x2).
  Eigen::Vector2d point(double xi) const;
  Eigen::Vector2d start() const { return point(lo); }
  Eigen::Vector2d end() const { return point(hi); }
  // A world point as (independent, dependent) coordinates: (x1, x2) for X1, (x2, x1) for X2.
  Eigen::Vector2d local(const Eigen::Vector2d& world) const;
  // The inverse of local() (it is its own inverse: a swap or nothing).
  Eigen::Vector2d world(const Eigen::Vector2d& local_point) const { return local(local_point); }
  // The unit vector along which c_0 moves the curve: (0, 1) for X1, (1, 0) for X2.
  Eigen::Vector2d dependent_direction() const;
  // Arc length over the domain (Gauss-Legendre on 16 panels).
  double length() const;
  bool in_domain(double xi) const { return xi >= lo && xi <= hi; }

  bool operator==(const Polynomial&) const = default;
};

std::ostream& operator<<(std::ostream& os, PolynomialAxis axis);
std::ostream& operator<<(std::ostream& os, const Polynomial& p);

// D'Alfonso et al. Fig. 2, the approximation error of `point` by p, in metres. For a point in the region p
// approximates (its independent coordinate inside the domain) it is the LMS residual |eta - p(xi)|;
// otherwise the distance to the nearer end point, min(|Q_m - pi|, |Q_M - pi|). The paper writes
// both as squares; their square roots are used so that the error compares with the thresholds
// rho and sigma, which the paper gives in metres.
double approximation_error(const Polynomial& p, const Eigen::Vector2d& point);

// A point for a weighted least-squares fit (D'Alfonso et al., §3.3).
struct WeightedPoint {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double weight = 1.0;
};

// The axis whose variate spreads the points most: X1 when their principal direction (weighted
// covariance) is within 45 degrees of the x1 axis, X2 otherwise.
PolynomialAxis principal_axis(const std::vector<WeightedPoint>& points);

struct PolynomialFit {
  Polynomial polynomial;
  double rms_residual = 0.0;  // weighted RMS of eta - p(xi), metres
  double max_residual = 0.0;  // largest |eta - p(xi)|
};

// Weighted least-squares m-th order polynomial along `axis` (D'Alfonso et al., §3.1, §3.3): minimises
// sum_k w_k (eta_k - p(xi_k))^2; the domain is [min xi_k, max xi_k]. Solved by QR in a centred
// and scaled variable, then expanded to the monomial coefficients b_m..b_1, c_0. nullopt when the
// points cannot determine an order-m polynomial (fewer than m + 1 distinct xi, a zero or negative
// weight sum, or a domain shorter than 1 mm).
std::optional<PolynomialFit> fit_polynomial(const std::vector<WeightedPoint>& points, int order, PolynomialAxis axis);

// d c_0 / d pi_k of the weighted LMS *position* of `shape` through the points (world frame,
// one 2-vector per point): with the shape held fixed, c_0 = sum_k w_k (eta_k - s(xi_k)) / sum_k w_k
// where s is p without c_0, so d c_0 / d(xi_k, eta_k) = w_k / W (-p'(xi_k), 1). This is the
// landmark generation function's gradient used for G_x and G_y (D'Alfonso et al., eq. (5)): the paper's
// state holds c_0 only, the shape being a landmark of the extraction step.
std::vector<Eigen::Vector2d> position_gradient(const Polynomial& shape, const std::vector<WeightedPoint>& points);

// How far p strays between `points`: the largest gap, over 201 samples of p's domain, between p
// and the broken line through the points sorted along p's independent variable (metres, along
// the dependent axis). 0 for fewer than two points.
double stray_between_points(const Polynomial& p, const std::vector<WeightedPoint>& points);

// `count` points equally spaced in the independent variable over the domain, ends included
// (the sets R of §3.1 and Q_0..Q_m of §3.3); one point is the domain's middle.
std::vector<Eigen::Vector2d> sample_equally(const Polynomial& p, int count);
// The same over a sub-interval [a, b] of the independent variable.
std::vector<Eigen::Vector2d> sample_equally(const Polynomial& p, double a, double b, int count);

// Points every `step` metres of curvilinear abscissa from Q_m, plus Q_M (D'Alfonso et al., §4's nu).
std::vector<Eigen::Vector2d> sample_arc_length(const Polynomial& p, double step);

// D'Alfonso et al. §3.2: a piecewise-linear approximation of p whose vertices lie on p and whose segments
// stay within `tolerance` metres of the curve (Douglas-Peucker on the curve sampled finely enough
// that the curve between samples cannot leave the tolerance). Returns the polyline's vertices,
// from Q_m to Q_M. Throws std::invalid_argument for a non-positive tolerance.
std::vector<Eigen::Vector2d> segment_polynomial(const Polynomial& p, double tolerance);

// Distance from a point to a polyline (to its nearest segment).
double distance_to_polyline(const Eigen::Vector2d& point, const std::vector<Eigen::Vector2d>& polyline);

// Where a ray from `origin` at world angle `angle` first meets p inside its domain (widened by
// `domain_margin` at both ends), within `max_distance`, and the derivatives of that distance:
// D'Alfonso et al. eq. (2)'s h for one sensor. By the implicit function theorem on
// F(t) = p(o_xi + t u_xi) - (o_eta + t u_eta) = 0: dt/dz = -(dF/dz) / (dF/dt).
struct RayHit {
  double distance = 0.0;                        // t
  double xi = 0.0;                              // where, in p's independent variable
  Eigen::Vector2d d_origin = Eigen::Vector2d::Zero();  // dt / d(origin x1, x2)
  double d_angle = 0.0;                         // dt / d angle (= dt / d theta for a sensor on a robot)
  double d_position = 0.0;                      // dt / d c_0
  double cos_incidence = 0.0;                   // |cos| of the angle between the ray and the curve's normal
};
std::optional<RayHit> intersect_ray(const Polynomial& p, const Eigen::Vector2d& origin, double angle,
                                    double max_distance, double domain_margin = 0.0);

// Real roots of the polynomial sum_i coeffs[i] t^i (lowest power first) in [a, b], ascending.
// Isolates the monotone pieces between the roots of the derivative (recursively) and bisects each.
std::vector<double> real_roots_in(const std::vector<double>& coeffs, double a, double b);

}  // namespace fleetmap::mapping
