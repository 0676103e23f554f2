#include "mapping/polynomial.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <stdexcept>

namespace fleetmap::mapping {

double Polynomial::value(double xi) const {
  double v = 0.0;
  for (double b : shape) v = v * xi + b;
  return v * xi + position;
}

double Polynomial::slope(double xi) const {
  double d = 0.0;
  const int m = order();
  for (int j = 0; j < m; ++j) d = d * xi + double(m - j) * shape[std::size_t(j)];
  return d;
}

Eigen::Vector2d Polynomial::point(double xi) const { return world({xi, value(xi)}); }

Eigen::Vector2d Polynomial::local(const Eigen::Vector2d& p) const {
  return axis == PolynomialAxis::X1 ? p : Eigen::Vector2d(p.y(), p.x());
}

Eigen::Vector2d Polynomial::dependent_direction() const {
  return axis == PolynomialAxis::X1 ? Eigen::Vector2d(0.0, 1.0) : Eigen::Vector2d(1.0, 0.0);
}

double Polynomial::length() const {
  // Gauss-Legendre, 5 nodes on each of 16 panels: exact enough for the smooth integrand sqrt(1 + p'^2).
  static constexpr double kNodes[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                       0.9061798459386640};
  static constexpr double kWeights[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                         0.4786286704993665, 0.2369268850561891};
  constexpr int kPanels = 16;
  if (!(hi > lo)) return 0.0;
  const double h = (hi - lo) / kPanels;
  double sum = 0.0;
  for (int k = 0; k < kPanels; ++k) {
    const double mid = lo + (k + 0.5) * h;
    for (int i = 0; i < 5; ++i) {
      const double d = slope(mid + 0.5 * h * kNodes[i]);
      sum += kWeights[i] * std::sqrt(1.0 + d * d);
    }
  }
  return 0.5 * h * sum;
}

std::ostream& operator<<(std::ostream& os, PolynomialAxis axis) {
  return os << (axis == PolynomialAxis::X1 ? "x1-variate" : "x2-variate");
}

std::ostream& operator<<(std::ostream& os, const Polynomial& p) {
  os << "Polynomial{" << p.axis << ", b = [";
  for (std::size_t i = 0; i < p.shape.size(); ++i) os << (i ? ", " : "") << p.shape[i];
  return os << "], c0 = " << p.position << ", domain [" << p.lo << ", " << p.hi << "]}";
}

double approximation_error(const Polynomial& p, const Eigen::Vector2d& point) {
  const Eigen::Vector2d q = p.local(point);
  if (p.in_domain(q.x())) return std::abs(q.y() - p.value(q.x()));
  return std::min((p.start() - point).norm(), (p.end() - point).norm());
}

PolynomialAxis principal_axis(const std::vector<WeightedPoint>& points) {
  double w = 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) {
    w += p.weight;
    mean += p.weight * p.position;
  }
  if (!(w > 0.0)) return PolynomialAxis::X1;
  mean /= w;
  double sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (const auto& p : points) {
    const Eigen::Vector2d d = p.position - mean;
    sxx += p.weight * d.x() * d.x();
    syy += p.weight * d.y() * d.y();
    sxy += p.weight * d.x() * d.y();
  }
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
  return std::abs(std::cos(angle)) >= std::abs(std::sin(angle)) ? PolynomialAxis::X1 : PolynomialAxis::X2;
}

std::optional<PolynomialFit> fit_polynomial(const std::vector<WeightedPoint>& points, int order, PolynomialAxis axis) {
  if (order < 0) throw std::invalid_argument("fit_polynomial: negative order");
  Polynomial p;
  p.axis = axis;
  const int n = static_cast<int>(points.size());
  const int cols = order + 1;
  std::vector<double> xi(static_cast<std::size_t>(n)), eta(static_cast<std::size_t>(n));
  double w_sum = 0.0, mean = 0.0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d q = p.local(points[std::size_t(k)].position);
    const double w = points[std::size_t(k)].weight;
    if (!(w >= 0.0) || !std::isfinite(w)) return std::nullopt;
    xi[std::size_t(k)] = q.x();
    eta[std::size_t(k)] = q.y();
    w_sum += w;
    mean += w * q.x();
    lo = std::min(lo, q.x());
    hi = std::max(hi, q.x());
  }
  if (n < cols || !(w_sum > 0.0) || !(hi - lo >= 1e-3)) return std::nullopt;
  {
    std::vector<double> sorted = xi;
    std::sort(sorted.begin(), sorted.end());
    int distinct = 1;
    for (std::size_t k = 1; k < sorted.size(); ++k) distinct += sorted[k] - sorted[k - 1] > 1e-9;
    if (distinct < cols) return std::nullopt;
  }
  mean /= w_sum;
  const double scale = std::max(hi - mean, mean - lo);
  // Least squares in u = (xi - mean) / scale, where the Vandermonde columns are well conditioned.
  Eigen::MatrixXd a(n, cols);
  Eigen::VectorXd b(n);
  for (int k = 0; k < n; ++k) {
    const double sw = std::sqrt(points[std::size_t(k)].weight);
    const double u = (xi[std::size_t(k)] - mean) / scale;
    double power = 1.0;
    for (int i = 0; i < cols; ++i, power *= u) a(k, i) = sw * power;
    b(k) = sw * eta[std::size_t(k)];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < cols) return std::nullopt;
  const Eigen::VectorXd coef_u = qr.solve(b);
  // Expand q(u) = sum_i a_i ((xi - mean) / scale)^i into monomials of xi:
  // d_j = sum_{i >= j} a_i C(i, j) (-mean)^(i - j) / scale^i.
  std::vector<double> d(std::size_t(cols), 0.0);
  for (int i = 0; i < cols; ++i) {
    const double ai = coef_u(i) / std::pow(scale, i);
    double binom = 1.0;  // C(i, j) for j = i, i - 1, ...
    double shift = 1.0;  // (-mean)^(i - j)
    for (int j = i; j >= 0; --j) {
      d[std::size_t(j)] += ai * binom * shift;
      binom = binom * double(j) / double(i - j + 1);
      shift *= -mean;
    }
  }
  p.position = d[0];
  p.shape.resize(std::size_t(order));
  for (int i = 1; i <= order; ++i) p.shape[std::size_t(order - i)] = d[std::size_t(i)];
  p.lo = lo;
  p.hi = hi;

  PolynomialFit fit;
  double sq = 0.0;
  for (int k = 0; k < n; ++k) {
    const double r = eta[std::size_t(k)] - p.value(xi[std::size_t(k)]);
    sq += points[std::size_t(k)].weight * r * r;
    fit.max_residual = std::max(fit.max_residual, std::abs(r));
  }
  fit.rms_residual = std::sqrt(sq / w_sum);
  fit.polynomial = std::move(p);
  return fit;
}

std::vector<Eigen::Vector2d> position_gradient(const Polynomial& shape, const std::vector<WeightedPoint>& points) {
  double w_sum = 0.0;
  for (const auto& p : points) w_sum += p.weight;
  std::vector<Eigen::Vector2d> out;
  out.reserve(points.size());
  for (const auto& p : points) {
    const double xi = shape.local(p.position).x();
    const double f = w_sum > 0.0 ? p.weight / w_sum : 0.0;
    out.push_back(shape.world(Eigen::Vector2d(-shape.slope(xi) * f, f)));
  }
  return out;
}

double stray_between_points(const Polynomial& p, const std::vector<WeightedPoint>& points) {
  std::vector<Eigen::Vector2d> local;
  local.reserve(points.size());
  for (const auto& q : points) local.push_back(p.local(q.position));
  std::sort(local.begin(), local.end(), [](const auto& a, const auto& b) { return a.x() < b.x(); });
  if (local.size() < 2) return 0.0;
  double worst = 0.0;
  std::size_t k = 1;
  constexpr int kSamples = 200;
  for (int i = 0; i <= kSamples; ++i) {
    const double xi = p.lo + (p.hi - p.lo) * double(i) / kSamples;
    while (k + 1 < local.size() && local[k].x() < xi) ++k;
    const Eigen::Vector2d& a = local[k - 1];
    const Eigen::Vector2d& b = local[k];
    const double f = b.x() > a.x() ? std::clamp((xi - a.x()) / (b.x() - a.x()), 0.0, 1.0) : 0.5;
    worst = std::max(worst, std::abs(p.value(xi) - (a.y() + f * (b.y() - a.y()))));
  }
  return worst;
}

std::vector<Eigen::Vector2d> sample_equally(const Polynomial& p, double a, double b, int count) {
  std::vector<Eigen::Vector2d> out;
  if (count <= 0) return out;
  if (count == 1) return {p.point(0.5 * (a + b))};
  out.reserve(std::size_t(count));
  for (int k = 0; k < count; ++k) out.push_back(p.point(a + (b - a) * double(k) / double(count - 1)));
  return out;
}

std::vector<Eigen::Vector2d> sample_equally(const Polynomial& p, int count) { return sample_equally(p, p.lo, p.hi, count); }

std::vector<Eigen::Vector2d> sample_arc_length(const Polynomial& p, double step) {
  if (!(step > 0.0)) throw std::invalid_argument("sample_arc_length: step must be positive");
  std::vector<Eigen::Vector2d> out = {p.start()};
  if (!(p.hi > p.lo)) return out;
  // Chord lengths on a grid fine enough that chords and arcs agree to far below the step.
  const int n = std::clamp(int(std::ceil(p.length() / step)) * 8, 256, 400000);
  double walked = 0.0, next = step;
  Eigen::Vector2d prev = p.start();
  double prev_xi = p.lo;
  for (int k = 1; k <= n; ++k) {
    const double xi = p.lo + (p.hi - p.lo) * double(k) / double(n);
    const Eigen::Vector2d q = p.point(xi);
    const double chord = (q - prev).norm();
    while (chord > 0.0 && walked + chord >= next) {
      const double f = (next - walked) / chord;
      out.push_back(p.point(prev_xi + f * (xi - prev_xi)));
      next += step;
    }
    walked += chord;
    prev = q;
    prev_xi = xi;
  }
  if ((out.back() - p.end()).norm() > 1e-9) out.push_back(p.end());
  return out;
}

namespace {

double distance_to_segment(const Eigen::Vector2d& q, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - q).norm();
}

}  // namespace

double distance_to_polyline(const Eigen::Vector2d& point, const std::vector<Eigen::Vector2d>& polyline) {
  if (polyline.empty()) return std::numeric_limits<double>::infinity();
  if (polyline.size() == 1) return (polyline[0] - point).norm();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < polyline.size(); ++i) best = std::min(best, distance_to_segment(point, polyline[i - 1], polyline[i]));
  return best;
}

std::vector<Eigen::Vector2d> segment_polynomial(const Polynomial& p, double tolerance) {
  if (!(tolerance > 0.0)) throw std::invalid_argument("segment_polynomial: tolerance must be positive");
  if (!(p.hi > p.lo)) return {p.start()};
  // Between samples h apart (in arc length) a curve of curvature k leaves its chord by at most
  // k h^2 / 8; samples every tolerance / 4 along a curve bent less than 1/tolerance keep that
  // below tolerance / 128, and the simplification works to 0.9 of the tolerance.
  const int n = std::clamp(int(std::ceil(4.0 * p.length() / tolerance)), 16, 200000);
  std::vector<Eigen::Vector2d> samples(std::size_t(n) + 1);
  for (int k = 0; k <= n; ++k) samples[std::size_t(k)] = p.point(p.lo + (p.hi - p.lo) * double(k) / double(n));
  // Douglas-Peucker with an explicit stack.
  std::vector<char> keep(samples.size(), 0);
  keep.front() = keep.back() = 1;
  std::vector<std::pair<std::size_t, std::size_t>> stack = {{0, samples.size() - 1}};
  const double limit = 0.9 * tolerance;
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    double worst = -1.0;
    std::size_t at = i;
    for (std::size_t k = i + 1; k < j; ++k) {
      const double d = distance_to_segment(samples[k], samples[i], samples[j]);
      if (d > worst) worst = d, at = k;
    }
    if (worst > limit) {
      keep[at] = 1;
      stack.push_back({i, at});
      stack.push_back({at, j});
    }
  }
  std::vector<Eigen::Vector2d> out;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (keep[k]) out.push_back(samples[k]);
  }
  return out;
}

namespace {

double horner(const std::vector<double>& c, double t) {
  double v = 0.0;
  for (auto it = c.rbegin(); it != c.rend(); ++it) v = v * t + *it;
  return v;
}

double bisect(const std::vector<double>& c, double lo, double hi, double f_lo) {
  for (int it = 0; it < 200 && hi - lo > 1e-15 * std::max(1.0, std::abs(lo) + std::abs(hi)); ++it) {
    const double mid = 0.5 * (lo + hi);
    const double f_mid = horner(c, mid);
    if (f_mid == 0.0) return mid;
    if ((f_mid < 0.0) == (f_lo < 0.0)) {
      lo = mid;
      f_lo = f_mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

}  // namespace

std::vector<double> real_roots_in(const std::vector<double>& coeffs, double a, double b) {
  std::vector<double> c = coeffs;
  while (!c.empty() && c.back() == 0.0) c.pop_back();
  std::vector<double> out;
  if (c.size() <= 1 || !(b >= a)) return out;
  if (c.size() == 2) {
    const double t = -c[0] / c[1];
    if (t >= a && t <= b) out.push_back(t);
    return out;
  }
  std::vector<double> derivative(c.size() - 1);
  for (std::size_t i = 1; i < c.size(); ++i) derivative[i - 1] = double(i) * c[i];
  std::vector<double> knots = {a};
  for (double t : real_roots_in(derivative, a, b)) {
    if (t > knots.back()) knots.push_back(t);
  }
  if (b > knots.back()) knots.push_back(b);
  const auto add = [&](double t) {
    if (out.empty() || t - out.back() > 1e-12 * std::max(1.0, std::abs(t))) out.push_back(t);
  };
  for (std::size_t k = 0; k + 1 < knots.size(); ++k) {
    const double l = knots[k], r = knots[k + 1];
    const double fl = horner(c, l), fr = horner(c, r);
    if (fl == 0.0) add(l);
    if ((fl < 0.0 && fr > 0.0) || (fl > 0.0 && fr < 0.0)) add(bisect(c, l, r, fl));
  }
  if (horner(c, knots.back()) == 0.0) add(knots.back());
  return out;
}

std::optional<RayHit> intersect_ray(const Polynomial& p, const Eigen::Vector2d& origin, double angle,
                                    double max_distance, double domain_margin) {
  const Eigen::Vector2d o = p.local(origin);
  const Eigen::Vector2d u = p.local(Eigen::Vector2d(std::cos(angle), std::sin(angle)));
  const Eigen::Vector2d du = p.local(Eigen::Vector2d(-std::sin(angle), std::cos(angle)));  // du / d angle
  const double lo = p.lo - domain_margin, hi = p.hi + domain_margin;
  std::optional<double> t;
  if (std::abs(u.x()) < 1e-12) {
    // The ray runs along the dependent axis: it meets the curve once, at xi = o_xi.
    if (o.x() >= lo && o.x() <= hi && std::abs(u.y()) > 0.0) {
      const double s = (p.value(o.x()) - o.y()) / u.y();
      if (s > 1e-9 && s <= max_distance) t = s;
    }
  } else {
    double t0 = (lo - o.x()) / u.x(), t1 = (hi - o.x()) / u.x();
    if (t0 > t1) std::swap(t0, t1);
    t0 = std::max(t0, 0.0);
    t1 = std::min(t1, max_distance);
    if (t0 <= t1) {
      // F(t) = p(o_xi + t u_xi) - (o_eta + t u_eta), composed by Horner's rule in polynomial arithmetic.
      std::vector<double> f = {p.shape.empty() ? p.position : p.shape[0]};
      const auto times_line = [&](const std::vector<double>& r) {
        std::vector<double> out(r.size() + 1, 0.0);
        for (std::size_t i = 0; i < r.size(); ++i) {
          out[i] += r[i] * o.x();
          out[i + 1] += r[i] * u.x();
        }
        return out;
      };
      for (int j = 1; j <= p.order(); ++j) {
        f = times_line(f);
        f[0] += j < p.order() ? p.shape[std::size_t(j)] : p.position;
      }
      if (f.size() < 2) f.resize(2, 0.0);
      f[0] -= o.y();
      f[1] -= u.y();
      for (double root : real_roots_in(f, t0, t1)) {
        if (root > 1e-9) {
          t = root;
          break;
        }
      }
    }
  }
  if (!t) return std::nullopt;
  RayHit hit;
  hit.distance = *t;
  hit.xi = o.x() + *t * u.x();
  const double d = p.slope(hit.xi);
  const double f_t = d * u.x() - u.y();
  if (std::abs(f_t) < 1e-12) return std::nullopt;
  hit.d_origin = p.world(Eigen::Vector2d(-d / f_t, 1.0 / f_t));
  hit.d_position = -1.0 / f_t;
  hit.d_angle = -(*t) * (d * du.x() - du.y()) / f_t;
  hit.cos_incidence = std::abs(f_t) / std::sqrt(1.0 + d * d);
  return hit;
}

}  // namespace fleetmap::mapping
