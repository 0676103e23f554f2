#include "localization/submap_matching.h"

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <climits>
#include <cstdint>
#include <limits>
#include <numbers>
#include <unordered_set>

#include "core/angle.h"

namespace fleetmap::localization {

namespace {

// The points turned by `angle` about the scan's origin, then moved by `t`, as grid cells.
std::vector<Eigen::Vector2i> cells_at(const PointCloud& points, double angle, const Eigen::Vector2d& t, double resolution) {
  const double c = std::cos(angle), s = std::sin(angle);
  std::vector<Eigen::Vector2i> out;
  out.reserve(points.size());
  for (const auto& p : points) {
    const double x = c * p.x() - s * p.y() + t.x(), y = s * p.x() + c * p.y() + t.y();
    out.emplace_back(int(std::floor(x / resolution)), int(std::floor(y / resolution)));
  }
  return out;
}

// The angles of a window: 0, then +-k steps out to the window's edge.
std::vector<double> window_angles(double window, double step) {
  const int n = step > 0.0 ? int(std::ceil(window / step)) : 0;
  std::vector<double> out;
  for (int k = -n; k <= n; ++k) out.push_back(k * step);
  return out;
}

// The grid seen by Ceres's bicubic interpolator: row y, column x, unknown cells at min probability.
class GridAdapter {
 public:
  enum { DATA_DIMENSION = 1 };
  // hit_field: the grid's surface field instead of its probabilities.
  GridAdapter(const SubmapGrid& grid, bool hit_field) : grid_(grid), hit_field_(hit_field) {}
  void GetValue(int row, int column, double* value) const {
    const int x = column + grid_.min_x(), y = row + grid_.min_y();
    *value = hit_field_ ? grid_.hit_field(x, y) : grid_.probability(x, y);
  }

 private:
  const SubmapGrid& grid_;
  bool hit_field_;
};

struct OccupiedSpaceCost {
  OccupiedSpaceCost(const SubmapGrid& grid, const PointCloud& points, double weight, bool hit_field)
      : grid_(grid), adapter_(grid, hit_field), interpolator_(adapter_), points_(points), weight_(weight) {}

  template <typename T>
  bool operator()(const T* pose, T* residual) const {
    const T c = ceres::cos(pose[2]), s = ceres::sin(pose[2]);
    const double r = grid_.resolution();
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const T x = c * points_[i].x() - s * points_[i].y() + pose[0];
      const T y = s * points_[i].x() + c * points_[i].y() + pose[1];
      T value;
      // Sample (row, column) is the centre of cell (min_x + column, min_y + row).
      interpolator_.Evaluate(y / r - 0.5 - double(grid_.min_y()), x / r - 0.5 - double(grid_.min_x()), &value);
      residual[i] = weight_ * (1.0 - value);
    }
    return true;
  }

  const SubmapGrid& grid_;
  GridAdapter adapter_;
  ceres::BiCubicInterpolator<GridAdapter> interpolator_;
  const PointCloud& points_;
  double weight_;
};

// The pull toward `target`: translation_weights (2x2, per metre) times the translation's offset,
// rotation_weight times the rotation's.
struct PriorCost {
  PriorCost(const core::Pose2& target, const Eigen::Matrix2d& translation_weights, double rotation_weight)
      : target_(target), tw_(translation_weights), rw_(rotation_weight) {}
  template <typename T>
  bool operator()(const T* pose, T* residual) const {
    const T dx = pose[0] - target_.x, dy = pose[1] - target_.y;
    residual[0] = tw_(0, 0) * dx + tw_(0, 1) * dy;
    residual[1] = tw_(1, 0) * dx + tw_(1, 1) * dy;
    residual[2] = rw_ * (pose[2] - target_.theta);
    return true;
  }
  core::Pose2 target_;
  Eigen::Matrix2d tw_;
  double rw_;
};

}  // namespace

double angular_search_step(const PointCloud& points, double resolution_m) {
  if (points.empty()) return 0.1;
  std::vector<double> d;
  d.reserve(points.size());
  for (const auto& p : points) d.push_back(p.norm());
  // The 95th percentile: a few far returns (a long corridor's end) would make the step tiny; they
  // land within a cell or two of their place at the best angle, which the refinement recovers.
  const auto k = d.begin() + std::ptrdiff_t(0.95 * double(d.size() - 1));
  std::nth_element(d.begin(), k, d.end());
  if (*k < resolution_m) return 0.1;
  return std::acos(1.0 - resolution_m * resolution_m / (2.0 * *k * *k));
}

PointCloud voxel_filter(const PointCloud& points, double cell_m) {
  std::unordered_set<std::uint64_t> seen;
  PointCloud out;
  for (const auto& p : points) {
    const auto x = std::uint64_t(std::uint32_t(std::int32_t(std::floor(p.x() / cell_m))));
    const auto y = std::uint64_t(std::uint32_t(std::int32_t(std::floor(p.y() / cell_m))));
    if (seen.insert((x << 32) | y).second) out.push_back(p);
  }
  return out;
}

double match_score(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& pose) {
  if (points.empty()) return 0.0;
  double sum = 0.0;
  for (const auto& c : cells_at(points, pose.theta, pose.position(), grid.resolution())) sum += grid.probability(c.x(), c.y());
  return sum / double(points.size());
}

Eigen::Matrix2d score_curvature(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& pose, double step_m,
                                bool hit_field) {
  // The score read through the refinement's bicubic interpolation: smooth at shifts below a cell.
  const GridAdapter adapter(grid, hit_field);
  const ceres::BiCubicInterpolator<GridAdapter> interpolator(adapter);
  const double r = grid.resolution();
  const auto score = [&](const core::Pose2& p) {
    const double c = std::cos(p.theta), s = std::sin(p.theta);
    double sum = 0.0;
    for (const auto& q : points) {
      const double x = c * q.x() - s * q.y() + p.x, y = s * q.x() + c * q.y() + p.y;
      double value = 0.0;
      interpolator.Evaluate(y / r - 0.5 - double(grid.min_y()), x / r - 0.5 - double(grid.min_x()), &value);
      sum += value;
    }
    return points.empty() ? 0.0 : sum / double(points.size());
  };
  const double center = score(pose);
  // Least squares for (a, b, c) in drop(u) = a ux^2 + 2 b ux uy + c uy^2 over unit directions u.
  constexpr int kDirections = 8;
  Eigen::Matrix<double, kDirections, 3> m;
  Eigen::Matrix<double, kDirections, 1> drop;
  for (int k = 0; k < kDirections; ++k) {
    const double a = std::numbers::pi * k / kDirections;
    const Eigen::Vector2d u(std::cos(a), std::sin(a));
    const auto shifted = [&](double sign) {
      return score(core::Pose2(pose.x + sign * step_m * u.x(), pose.y + sign * step_m * u.y(), pose.theta));
    };
    drop[k] = (center - 0.5 * (shifted(1.0) + shifted(-1.0))) / (step_m * step_m);
    m.row(k) << u.x() * u.x(), 2.0 * u.x() * u.y(), u.y() * u.y();
  }
  const Eigen::Vector3d abc = m.colPivHouseholderQr().solve(drop);
  Eigen::Matrix2d a;
  a << abc[0], abc[1], abc[1], abc[2];
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(a);
  const Eigen::Vector2d clamped = eigen.eigenvalues().cwiseMax(0.0);
  return eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
}

double score_advantage(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& a, const core::Pose2& b) {
  if (points.size() < 2) return 0.0;
  const auto ca = cells_at(points, a.theta, a.position(), grid.resolution());
  const auto cb = cells_at(points, b.theta, b.position(), grid.resolution());
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = double(grid.probability(ca[i].x(), ca[i].y())) - double(grid.probability(cb[i].x(), cb[i].y()));
    sum += d, sum2 += d * d;
  }
  const double n = double(points.size()), mean = sum / n;
  const double error = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
  if (error == 0.0) return mean > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  return mean / error;
}

namespace {

// correlative_match over a cell reader `value(x, y)` whose values never exceed `top`.
template <typename Value>
MatchResult correlative_search(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& prior,
                               const CorrelativeOptions& o, const Value& value, double top) {
  MatchResult best{prior, -1.0};
  if (points.empty()) return {prior, 0.0};
  const double r = grid.resolution();
  const int w = int(std::ceil(o.linear_window_m / r));
  const double step = angular_search_step(points, r);
  const std::size_t np = points.size();
  const double n = double(np);
  auto sum_at = [&](const std::vector<Eigen::Vector2i>& cells, int dx, int dy, std::size_t from, std::size_t to, double sum) {
    for (std::size_t i = from; i < to; ++i) sum += value(cells[i].x() + dx, cells[i].y() + dy);
    return sum;
  };
  // The prior pose's own score (penalty 0): a candidate that cannot reach it is never the answer,
  // nor one that cannot beat the best so far; both are told early from a partial sum of the points
  // (the margin covers the sum's rounding), which leaves the answer as the full search's.
  const double floor_score = sum_at(cells_at(points, prior.theta + 0.0, prior.position(), r), 0, 0, 0, np, 0.0) / n;
  constexpr std::size_t kBlock = 32;
  constexpr double kMargin = 1.0 + 1e-9;
  for (const double da : window_angles(o.angular_window_rad, step)) {
    const auto cells = cells_at(points, prior.theta + da, prior.position(), r);
    for (int dy = -w; dy <= w; ++dy) {
      for (int dx = -w; dx <= w; ++dx) {
        const double d = std::hypot(dx * r, dy * r);
        const double penalty = d * o.translation_weight + std::abs(da) * o.rotation_weight;
        const double factor = std::exp(-penalty * penalty);
        double sum = 0.0;
        bool hopeless = false;
        for (std::size_t i = 0; i < np && !hopeless;) {
          const std::size_t end = std::min(np, i + kBlock);
          sum = sum_at(cells, dx, dy, i, end, sum);
          i = end;
          if (i < np) {
            const double most = (sum + top * double(np - i)) / n * factor * kMargin;
            hopeless = most < floor_score || most <= best.score;
          }
        }
        if (hopeless) continue;
        const double score = sum / n * factor;
        if (score > best.score) best = {core::Pose2(prior.x + dx * r, prior.y + dy * r, prior.theta + da), score};
      }
    }
  }
  best.pose.theta = core::normalize_angle(best.pose.theta);
  return best;
}

}  // namespace

MatchResult correlative_match(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& prior,
                              const CorrelativeOptions& o) {
  if (o.hit_field) {
    return correlative_search(grid, points, prior, o, [&](int x, int y) { return grid.hit_field(x, y); }, 1.0);
  }
  // A cell reads at most this (the probabilities are clamped, then stored as floats).
  const double top = double(float(grid.options().max_probability));
  return correlative_search(grid, points, prior, o, [&](int x, int y) { return grid.probability(x, y); }, top);
}

PrecomputedGrids::PrecomputedGrids(const SubmapGrid& grid, int depth) : resolution_(grid.resolution()) {
  // The levels are held over the known cells' bounds, and 2^depth - 1 cells below them (where a
  // square reaches into them): every other cell of every level is unknown.
  int lo_x = INT32_MAX, lo_y = INT32_MAX, hi_x = INT32_MIN, hi_y = INT32_MIN;
  for (int y = grid.min_y(); y < grid.min_y() + grid.height(); ++y) {
    for (int x = grid.min_x(); x < grid.min_x() + grid.width(); ++x) {
      if (grid.known(x, y)) lo_x = std::min(lo_x, x), lo_y = std::min(lo_y, y), hi_x = std::max(hi_x, x), hi_y = std::max(hi_y, y);
    }
  }
  if (lo_x > hi_x) lo_x = grid.min_x(), lo_y = grid.min_y(), hi_x = lo_x - 1, hi_y = lo_y - 1;
  const int pad = (1 << depth) - 1;
  min_x_ = lo_x - pad, min_y_ = lo_y - pad;
  width_ = hi_x - lo_x + 1 + pad, height_ = hi_y - lo_y + 1 + pad;
  unknown_ = std::uint8_t(std::lround(255.0 * grid.probability(grid.min_x() - 1, grid.min_y() - 1)));
  std::vector<std::uint8_t> level(std::size_t(width_) * std::size_t(height_));
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      level[std::size_t(y) * std::size_t(width_) + std::size_t(x)] =
          std::uint8_t(std::lround(255.0 * grid.probability(x + min_x_, y + min_y_)));
    }
  }
  max_value_ = std::max<int>(unknown_, level.empty() ? 0 : *std::max_element(level.begin(), level.end()));
  levels_.push_back(std::move(level));
  // Level h from level h-1: the largest of four cells half the width apart, taken along rows then
  // along columns (cells past the far edges are unknown).
  const std::size_t wd = std::size_t(width_);
  std::vector<std::uint8_t> along(levels_.back().size());
  for (int h = 1; h <= depth; ++h) {
    const int s = 1 << (h - 1);
    const std::vector<std::uint8_t>& prev = levels_.back();
    for (std::size_t y = 0; y < std::size_t(height_); ++y) {
      const std::uint8_t* in = prev.data() + y * wd;
      std::uint8_t* out = along.data() + y * wd;
      for (int x = 0; x < width_; ++x) out[x] = std::max(in[x], x + s < width_ ? in[x + s] : unknown_);
    }
    std::vector<std::uint8_t> next(along.size());
    for (int y = 0; y < height_; ++y) {
      const std::uint8_t* a = along.data() + std::size_t(y) * wd;
      const std::uint8_t* b = y + s < height_ ? along.data() + std::size_t(y + s) * wd : nullptr;
      std::uint8_t* out = next.data() + std::size_t(y) * wd;
      for (int x = 0; x < width_; ++x) out[x] = std::max(a[x], b ? b[x] : unknown_);
    }
    levels_.push_back(std::move(next));
  }
}

std::optional<MatchResult> branch_and_bound_match(const PrecomputedGrids& grids, const PointCloud& points,
                                                  const core::Pose2& center, const BranchAndBoundOptions& o) {
  if (points.empty()) return std::nullopt;
  const double r = grids.resolution();
  const int w = int(std::ceil(o.linear_window_m / r));
  const auto angles = window_angles(o.angular_window_rad, angular_search_step(points, r));
  // The points taken in a stride through the scan, so that every prefix is spread over all of it:
  // a candidate's partial sum tells early that it cannot beat the best, and the sum (of integers)
  // does not depend on the order.
  const std::size_t np = points.size();
  constexpr std::size_t kStride = 16;
  PointCloud spread;
  spread.reserve(np);
  for (std::size_t first = 0; first < kStride; ++first) {
    for (std::size_t i = first; i < np; i += kStride) spread.push_back(points[i]);
  }
  // Each rotated scan's cells (counted from the levels' first cell), their offsets in the grids'
  // rows (the levels share one layout) and their bounds, so that a candidate wholly inside the
  // grids reads cells without bounds checks (the searches' inner loop).
  const std::ptrdiff_t row = grids.width();
  std::vector<Eigen::Vector2i> cells;
  std::vector<std::ptrdiff_t> offsets;
  std::vector<Eigen::Vector4i> bounds;
  cells.reserve(angles.size() * np);
  offsets.reserve(angles.size() * np);
  for (const double da : angles) {
    Eigen::Vector4i b(INT32_MAX, INT32_MAX, INT32_MIN, INT32_MIN);
    for (const auto& p : cells_at(spread, center.theta + da, center.position(), r)) {
      cells.emplace_back(p.x() - grids.min_x(), p.y() - grids.min_y());
      offsets.push_back(std::ptrdiff_t(p.y()) * row + p.x());
      b = Eigen::Vector4i(std::min(b[0], p.x()), std::min(b[1], p.y()), std::max(b[2], p.x()), std::max(b[3], p.y()));
    }
    bounds.push_back(b);
  }

  struct Candidate {
    int scan = 0, dx = 0, dy = 0;
    double score = 0.0;
  };
  const double n = double(np) * 255.0;
  const int top_value = grids.max_value();
  // The prior's factor at the pose of the candidate's region nearest the centre, so that the
  // region's score still bounds every pose in it.
  auto prior = [&](const Candidate& c, int level) {
    if (o.translation_weight == 0.0 && o.rotation_weight == 0.0) return 1.0;
    const int size = (1 << level) - 1;
    const int nx = c.dx > 0 ? c.dx : (c.dx + size < 0 ? c.dx + size : 0);
    const int ny = c.dy > 0 ? c.dy : (c.dy + size < 0 ? c.dy + size : 0);
    const double penalty = std::hypot(nx * r, ny * r) * o.translation_weight + std::abs(angles[std::size_t(c.scan)]) * o.rotation_weight;
    return std::exp(-penalty * penalty);
  };
  auto inside = [&](const Candidate& low, const Candidate& high) {
    const auto& b = bounds[std::size_t(low.scan)];
    return b[0] + low.dx >= grids.min_x() && b[1] + low.dy >= grids.min_y() && b[2] + high.dx < grids.min_x() + grids.width() &&
           b[3] + high.dy < grids.min_y() + grids.height();
  };
  // A cell's value by its coordinates from the levels' first cell: unknown outside them.
  const int unknown = grids.value(0, grids.min_x() - 1, grids.min_y() - 1);
  const unsigned held_x = unsigned(grids.width()), held_y = unsigned(grids.height());
  const bool none_held = held_x == 0 || held_y == 0;
  auto checked = [&](const std::uint8_t* data, int x, int y) {
    const bool in = unsigned(x) < held_x && unsigned(y) < held_y;
    const int v = data[in ? std::ptrdiff_t(y) * row + x : 0];
    return in ? v : unknown;
  };
  // Scoring sets a candidate's score at `level`; or, once the points read so far show that it
  // cannot exceed `bound`, an upper bound of it that does not exceed `bound` either (such a
  // candidate is never explored: the best score only rises). Points are read in blocks between
  // such checks.
  constexpr std::size_t kBlock = 32;
  auto score = [&](Candidate& c, int level, double bound) {
    const double factor = prior(c, level);
    const std::size_t first = std::size_t(c.scan) * np;
    const bool fast = inside(c, c);
    const std::uint8_t* level_data = grids.level_data(level);
    const std::uint8_t* data = level_data + std::ptrdiff_t(c.dy - grids.min_y()) * row + (c.dx - grids.min_x());
    int sum = 0;
    for (std::size_t i = 0; i < np;) {
      const std::size_t end = std::min(np, i + kBlock);
      if (fast) {
        for (; i < end; ++i) sum += data[offsets[first + i]];
      } else if (none_held) {
        sum += unknown * int(end - i), i = end;
      } else {
        for (; i < end; ++i) sum += checked(level_data, cells[first + i].x() + c.dx, cells[first + i].y() + c.dy);
      }
      if (i < np) {
        const double most = double(sum + top_value * int(np - i)) / n * factor;
        if (most <= bound) {
          c.score = most;
          return;
        }
      }
    }
    c.score = double(sum) / n * factor;
  };
  // The four quarters (dx, dy), (dx + s, dy), (dx, dy + s), (dx + s, dy + s) of a candidate
  // scored in one pass over their points.
  auto score_quarters = [&](std::array<Candidate, 4>& q, int level, double bound) {
    std::array<double, 4> factor{};
    for (std::size_t k = 0; k < 4; ++k) factor[k] = prior(q[k], level);
    const std::size_t first = std::size_t(q[0].scan) * np;
    const bool fast = inside(q[0], q[3]);
    const std::uint8_t* level_data = grids.level_data(level);
    const std::uint8_t* data = level_data + std::ptrdiff_t(q[0].dy - grids.min_y()) * row + (q[0].dx - grids.min_x());
    const int s = q[1].dx - q[0].dx;
    const std::ptrdiff_t sx = s, sy = std::ptrdiff_t(s) * row;
    std::array<int, 4> sum{};
    for (std::size_t i = 0; i < np;) {
      const std::size_t end = std::min(np, i + kBlock);
      if (fast) {
        for (; i < end; ++i) {
          const std::uint8_t* p = data + offsets[first + i];
          sum[0] += p[0], sum[1] += p[sx], sum[2] += p[sy], sum[3] += p[sy + sx];
        }
      } else {
        for (; i < end; ++i) {
          const int x = cells[first + i].x() + q[0].dx, y = cells[first + i].y() + q[0].dy;
          sum[0] += checked(level_data, x, y), sum[1] += checked(level_data, x + s, y);
          sum[2] += checked(level_data, x, y + s), sum[3] += checked(level_data, x + s, y + s);
        }
      }
      if (i < np) {
        std::array<double, 4> most{};
        bool all = true;
        for (std::size_t k = 0; k < 4; ++k) {
          most[k] = double(sum[k] + top_value * int(np - i)) / n * factor[k];
          all = all && most[k] <= bound;
        }
        if (all) {
          for (std::size_t k = 0; k < 4; ++k) q[k].score = most[k];
          return;
        }
      }
    }
    for (std::size_t k = 0; k < 4; ++k) q[k].score = double(sum[k]) / n * factor[k];
  };
  auto by_score = [](const Candidate& a, const Candidate& b) { return a.score > b.score; };

  const int top = grids.depth();
  std::vector<Candidate> start;
  const int top_step = 1 << top;
  for (int k = 0; k < int(angles.size()); ++k) {
    for (int dy = -w; dy <= w; dy += top_step) {
      for (int dx = -w; dx <= w; dx += top_step) {
        Candidate c{k, dx, dy, 0.0};
        score(c, top, -std::numeric_limits<double>::infinity());
        start.push_back(c);
      }
    }
  }
  std::sort(start.begin(), start.end(), by_score);

  std::optional<Candidate> best;
  double best_score = o.min_score;
  // Whether every offset a candidate of `level` covers lies in the excluded disc (its four corners
  // do, and the disc is convex).
  auto excluded = [&](const Candidate& c, int level) {
    if (!o.exclude_center) return false;
    const int size = (1 << level) - 1;
    for (int cy : {c.dy, c.dy + size}) {
      for (int cx : {c.dx, c.dx + size}) {
        if ((Eigen::Vector2d(center.x + cx * r, center.y + cy * r) - *o.exclude_center).norm() > o.exclude_radius_m) return false;
      }
    }
    return true;
  };
  // Depth-first: a candidate at level h covers offsets [dx, dx + 2^h) x [dy, dy + 2^h), and its
  // level-h score bounds every pose it covers. Candidates best first, equal scores in the order made.
  auto search = [&](auto&& self, const Candidate* candidates, std::size_t count, int level) -> void {
    for (std::size_t i = 0; i < count; ++i) {
      const Candidate& c = candidates[i];
      if (c.score <= best_score) break;
      if (excluded(c, level)) continue;
      if (level == 0) {
        best = c, best_score = c.score;
        continue;
      }
      const int half = 1 << (level - 1);
      std::array<Candidate, 4> children;
      std::size_t k = 0;
      for (int oy : {0, half}) {
        for (int ox : {0, half}) {
          const Candidate child{c.scan, c.dx + ox, c.dy + oy, 0.0};
          if (child.dx <= w && child.dy <= w && !excluded(child, level - 1)) children[k++] = child;
        }
      }
      if (k == 4 && !none_held) {
        score_quarters(children, level - 1, best_score);
      } else {
        for (std::size_t j = 0; j < k; ++j) score(children[j], level - 1, best_score);
      }
      // Insertion sort: stable, as std::sort is for so few.
      for (std::size_t j = 1; j < k; ++j) {
        const Candidate v = children[j];
        std::size_t m = j;
        for (; m > 0 && v.score > children[m - 1].score; --m) children[m] = children[m - 1];
        children[m] = v;
      }
      self(self, children.data(), k, level - 1);
    }
  };
  search(search, start.data(), start.size(), top);
  if (!best) return std::nullopt;
  return MatchResult{core::Pose2(center.x + best->dx * r, center.y + best->dy * r,
                                 core::normalize_angle(center.theta + angles[std::size_t(best->scan)])),
                     best->score};
}

core::Pose2 refine_match(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& initial,
                         const core::Pose2& target, const RefineOptions& o) {
  if (points.empty()) return initial;
  double pose[3] = {initial.x, initial.y, initial.theta};
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<OccupiedSpaceCost, ceres::DYNAMIC, 3>(
                               new OccupiedSpaceCost(grid, points, o.occupied_weight / std::sqrt(double(points.size())), o.hit_field),
                               int(points.size())),
                           nullptr, pose);
  Eigen::Matrix2d translation_weights = o.translation_weight * Eigen::Matrix2d::Identity();
  Eigen::Vector2d anchor = target.position();
  if (o.fixed_translation_weight >= 0.0) {
    // The curvature is the whole scan's: points evenly spread through it estimate it for less.
    constexpr std::size_t kCurvaturePoints = 100;
    PointCloud spread;
    const std::size_t stride = std::max<std::size_t>(1, points.size() / kCurvaturePoints);
    for (std::size_t i = 0; i < points.size(); i += stride) spread.push_back(points[i]);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(score_curvature(grid, spread, initial, 0.5 * grid.resolution(), o.hit_field));
    const double largest = eigen.eigenvalues()[1];
    Eigen::Vector2d w = Eigen::Vector2d::Constant(o.translation_weight);
    Eigen::Vector2d fixed = Eigen::Vector2d::Zero();
    if (largest > 0.0) {
      // A residual's weight is the square root of its information, and the curvature is one.
      for (int i = 0; i < 2; ++i) {
        fixed[i] = std::sqrt(std::max(0.0, eigen.eigenvalues()[i]) / largest);
        w[i] = fixed[i] * o.fixed_translation_weight + (1.0 - fixed[i]) * o.translation_weight;
      }
    }
    translation_weights = eigen.eigenvectors() * w.asDiagonal() * eigen.eigenvectors().transpose();
    // The pull's anchor moves from target's translation to initial's by the same share: initial is
    // a search's answer that already weighed the prediction, and pulling it back toward the
    // prediction where the scan fixes the pose counts the prediction twice.
    anchor += eigen.eigenvectors() * fixed.asDiagonal() * eigen.eigenvectors().transpose() * (initial.position() - target.position());
  }
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost, 3, 3>(
                               new PriorCost(core::Pose2(anchor.x(), anchor.y(), initial.theta), translation_weights, o.rotation_weight)),
                           nullptr, pose);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = o.max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return core::Pose2(pose[0], pose[1], core::normalize_angle(pose[2]));
}

}  // namespace fleetmap::localization
