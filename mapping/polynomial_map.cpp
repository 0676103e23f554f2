#include "mapping/polynomial_map.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <unordered_map>

namespace fleetmap::mapping {

std::vector<Polynomial> PolynomialMap::polynomials() const {
  std::vector<Polynomial> out;
  out.reserve(landmarks.size());
  for (const auto& l : landmarks) out.push_back(l.polynomial);
  return out;
}

int PolynomialMap::index_of(long id) const {
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    if (landmarks[i].id == id) return int(i);
  }
  return -1;
}

PolynomialMap::Best PolynomialMap::best_approximation(const Eigen::Vector2d& point) const {
  Best best;
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    const double e = approximation_error(landmarks[i].polynomial, point);
    if (e < best.error) best = {int(i), e};
  }
  return best;
}

int PolynomialMap::densest_cluster(const Eigen::Vector2d& point, double radius) const {
  int best = -1, best_count = 0;
  const double r2 = radius * radius;
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    int count = 0;
    for (const auto& q : clusters[c].points) count += (q.position - point).squaredNorm() <= r2;
    if (count > best_count) best = int(c), best_count = count;
  }
  return best;
}

std::optional<Overlap> overlap(const Polynomial& a, const Polynomial& b) {
  constexpr int kSamples = 65;
  std::optional<Overlap> out;
  Eigen::Vector2d prev = Eigen::Vector2d::Zero();
  for (int k = 0; k < kSamples; ++k) {
    const double xi = a.lo + (a.hi - a.lo) * double(k) / double(kSamples - 1);
    const Eigen::Vector2d q = a.point(xi);
    if (b.in_domain(b.local(q).x())) {
      if (!out) {
        out = Overlap{xi, xi, 0.0};
      } else {
        out->length += (q - prev).norm();
        out->hi = xi;
      }
    }
    prev = q;
  }
  if (out) {
    Polynomial part = a;
    part.lo = out->lo;
    part.hi = out->hi;
    out->length = part.length();
  }
  return out;
}

double tangent_angle(const Polynomial& a, double a_xi, const Polynomial& b) {
  const Eigen::Vector2d ta = a.world(Eigen::Vector2d(1.0, a.slope(a_xi))).normalized();
  const double b_xi = b.local(a.point(a_xi)).x();
  const Eigen::Vector2d tb = b.world(Eigen::Vector2d(1.0, b.slope(b_xi))).normalized();
  return std::acos(std::clamp(std::abs(ta.dot(tb)), 0.0, 1.0));
}

double rms_residual(const Polynomial& b, const std::vector<Eigen::Vector2d>& points) {
  if (points.empty()) return 0.0;
  double sq = 0.0;
  for (const auto& p : points) {
    const Eigen::Vector2d q = b.local(p);
    const double r = q.y() - b.value(q.x());
    sq += r * r;
  }
  return std::sqrt(sq / double(points.size()));
}

double distance_to_walls(const Eigen::Vector2d& point, const std::vector<WallSegment>& walls) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& w : walls) {
    const Eigen::Vector2d ab = w.b - w.a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((point - w.a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, (w.a + t * ab - point).squaredNorm());
  }
  return std::sqrt(best);
}

MappingError mapping_error(const std::vector<Polynomial>& polynomials, const core::Transform2& to_truth,
                           const std::vector<WallSegment>& walls, double step) {
  MappingError e;
  e.polynomials = int(polynomials.size());
  if (polynomials.empty()) return e;
  double total = 0.0;
  for (const auto& p : polynomials) {
    double nu_q = 0.0;
    for (const auto& q : sample_arc_length(p, step)) {
      const double d = distance_to_walls(to_truth * q, walls);
      nu_q += d;
      e.max_distance = std::max(e.max_distance, d);
      ++e.samples;
    }
    total += nu_q;
  }
  e.nu = total / double(polynomials.size());
  e.mean_distance = e.samples > 0 ? total / double(e.samples) : 0.0;
  return e;
}

double boundary_coverage(const std::vector<Polynomial>& polynomials, const core::Transform2& to_truth,
                         const std::vector<WallSegment>& walls, double tolerance, double step) {
  // Polynomial samples hashed into cells of the tolerance's size: a wall point is covered when a
  // sample within the tolerance lies in its cell or a neighbouring one.
  std::unordered_map<std::int64_t, std::vector<Eigen::Vector2d>> cells;
  const auto key = [&](long cx, long cy) { return (std::int64_t(cx) << 32) ^ std::int64_t(std::uint32_t(cy)); };
  const double sample_step = std::min(step, 0.5 * tolerance);
  for (const auto& p : polynomials) {
    for (const auto& q : sample_arc_length(p, sample_step)) {
      const Eigen::Vector2d w = to_truth * q;
      cells[key(long(std::floor(w.x() / tolerance)), long(std::floor(w.y() / tolerance)))].push_back(w);
    }
  }
  long total = 0, covered = 0;
  for (const auto& wall : walls) {
    const double len = (wall.b - wall.a).norm();
    const int n = std::max(1, int(std::ceil(len / step)));
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d q = wall.a + (wall.b - wall.a) * ((double(k) + 0.5) / double(n));
      ++total;
      const long cx = long(std::floor(q.x() / tolerance)), cy = long(std::floor(q.y() / tolerance));
      bool hit = false;
      for (long dy = -1; dy <= 1 && !hit; ++dy) {
        for (long dx = -1; dx <= 1 && !hit; ++dx) {
          const auto it = cells.find(key(cx + dx, cy + dy));
          if (it == cells.end()) continue;
          for (const auto& s : it->second) {
            if ((s - q).squaredNorm() <= tolerance * tolerance) {
              hit = true;
              break;
            }
          }
        }
      }
      covered += hit;
    }
  }
  return total > 0 ? double(covered) / double(total) : 0.0;
}

}  // namespace fleetmap::mapping
