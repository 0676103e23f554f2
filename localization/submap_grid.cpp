#include "localization/submap_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fleetmap::localization {

namespace {

double odds(double p) { return p / (1.0 - p); }

// Calls visit(x, y, last) for each cell (of side r) the segment from a to b crosses, in order, the
// one holding b last (Amanatides & Woo's traversal).
template <typename Visit>
void traverse(const Eigen::Vector2d& a_m, const Eigen::Vector2d& b_m, double r, const Visit& visit) {
  const Eigen::Vector2d a = a_m / r, b = b_m / r;
  int x = int(std::floor(a.x())), y = int(std::floor(a.y()));
  const int ex = int(std::floor(b.x())), ey = int(std::floor(b.y()));
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double tdx = dx != 0.0 ? std::abs(1.0 / dx) : kInf, tdy = dy != 0.0 ? std::abs(1.0 / dy) : kInf;
  double tmx = dx > 0 ? (x + 1 - a.x()) * tdx : (dx < 0 ? (a.x() - x) * tdx : kInf);
  double tmy = dy > 0 ? (y + 1 - a.y()) * tdy : (dy < 0 ? (a.y() - y) * tdy : kInf);
  const int steps = std::abs(ex - x) + std::abs(ey - y);
  for (int i = 0; i < steps; ++i) {
    visit(x, y, false);
    if (tmx < tmy) {
      tmx += tdx, x += sx;
    } else {
      tmy += tdy, y += sy;
    }
  }
  visit(x, y, true);
}

}  // namespace

SubmapGrid::SubmapGrid(const SubmapGridOptions& options) : options_(options) {
  const double sigma = options_.hit_field_sigma_m, r = options_.resolution_m;
  if (sigma <= 0.0) return;
  const int reach = int(std::ceil(3.0 * sigma / r));
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const double d2 = (dx * dx + dy * dy) * r * r;
      if (d2 <= 9.0 * sigma * sigma) kernel_.push_back({dx, dy, float(std::exp(-0.5 * d2 / (sigma * sigma)))});
    }
  }
}

Eigen::Vector2i SubmapGrid::cell_of(const Eigen::Vector2d& p) const {
  return {int(std::floor(p.x() / options_.resolution_m)), int(std::floor(p.y() / options_.resolution_m))};
}

bool SubmapGrid::known(int x, int y) const {
  const int ix = x - min_x_, iy = y - min_y_;
  if (ix < 0 || iy < 0 || ix >= width_ || iy >= height_) return false;
  return cells_[std::size_t(iy) * std::size_t(width_) + std::size_t(ix)] != 0.0f;
}

void SubmapGrid::grow_to(int lo_x, int lo_y, int hi_x, int hi_y) {
  if (width_ > 0 && lo_x >= min_x_ && lo_y >= min_y_ && hi_x < min_x_ + width_ && hi_y < min_y_ + height_) return;
  // Grow by a margin so that a moving robot does not reallocate at every scan.
  const int margin = 64;
  const int nlo_x = width_ > 0 ? std::min(min_x_, lo_x - margin) : lo_x - margin;
  const int nlo_y = width_ > 0 ? std::min(min_y_, lo_y - margin) : lo_y - margin;
  const int nhi_x = width_ > 0 ? std::max(min_x_ + width_ - 1, hi_x + margin) : hi_x + margin;
  const int nhi_y = width_ > 0 ? std::max(min_y_ + height_ - 1, hi_y + margin) : hi_y + margin;
  const int nw = nhi_x - nlo_x + 1, nh = nhi_y - nlo_y + 1;
  std::vector<float> cells(std::size_t(nw) * std::size_t(nh), 0.0f);
  std::vector<std::uint32_t> stamp(cells.size(), 0);
  const bool with_field = !kernel_.empty();
  std::vector<float> field(with_field ? cells.size() : 0, 0.0f);
  for (int y = 0; y < height_; ++y) {
    const std::size_t from = std::size_t(y) * std::size_t(width_);
    const std::size_t to = std::size_t(y + min_y_ - nlo_y) * std::size_t(nw) + std::size_t(min_x_ - nlo_x);
    std::copy_n(cells_.begin() + std::ptrdiff_t(from), width_, cells.begin() + std::ptrdiff_t(to));
    std::copy_n(stamp_.begin() + std::ptrdiff_t(from), width_, stamp.begin() + std::ptrdiff_t(to));
    if (with_field && !field_.empty()) std::copy_n(field_.begin() + std::ptrdiff_t(from), width_, field.begin() + std::ptrdiff_t(to));
  }
  cells_ = std::move(cells);
  stamp_ = std::move(stamp);
  field_ = std::move(field);
  min_x_ = nlo_x, min_y_ = nlo_y, width_ = nw, height_ = nh;
}

void SubmapGrid::release_insertion_state() {
  std::vector<std::uint32_t>().swap(stamp_);
  std::vector<float>().swap(field_);
  kernel_.clear();
}

void SubmapGrid::add_surface(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  if (kernel_.empty() || field_.empty()) return;
  const auto stamp = [&](int cx, int cy) {
    for (const auto& k : kernel_) {
      const int ix = cx + k.dx - min_x_, iy = cy + k.dy - min_y_;
      if (ix < 0 || iy < 0 || ix >= width_ || iy >= height_) continue;
      float& f = field_[std::size_t(iy) * std::size_t(width_) + std::size_t(ix)];
      f = std::max(f, k.value);
    }
  };
  traverse(a, b, options_.resolution_m, [&](int x, int y, bool) { stamp(x, y); });
}

void SubmapGrid::update(int x, int y, double odds_factor) {
  const int ix = x - min_x_, iy = y - min_y_;
  if (ix < 0 || iy < 0 || ix >= width_ || iy >= height_) return;
  const std::size_t i = std::size_t(iy) * std::size_t(width_) + std::size_t(ix);
  if (stamp_[i] == scan_) return;
  stamp_[i] = scan_;
  float& p = cells_[i];
  // An unknown cell starts at even odds.
  if (p == 0.0f) ++known_;
  const double prior = p == 0.0f ? 1.0 : odds(p);
  const double o = prior * odds_factor;
  p = float(std::clamp(o / (1.0 + o), options_.min_probability, options_.max_probability));
}

void SubmapGrid::insert(const Eigen::Vector2d& sensor, const std::vector<Eigen::Vector2d>& hits) {
  if (hits.empty()) return;
  if (stamp_.size() != cells_.size()) stamp_.assign(cells_.size(), 0);  // scan_ is above 0 from now on
  ++scan_;
  const Eigen::Vector2i s = cell_of(sensor);
  int lo_x = s.x(), lo_y = s.y(), hi_x = s.x(), hi_y = s.y();
  for (const auto& h : hits) {
    const Eigen::Vector2i c = cell_of(h);
    lo_x = std::min(lo_x, c.x()), lo_y = std::min(lo_y, c.y()), hi_x = std::max(hi_x, c.x()), hi_y = std::max(hi_y, c.y());
  }
  grow_to(lo_x, lo_y, hi_x, hi_y);
  const double hit = odds(options_.hit_probability), miss = odds(options_.miss_probability);
  for (const auto& h : hits) {
    const Eigen::Vector2i c = cell_of(h);
    update(c.x(), c.y(), hit);
  }
  // Misses: every cell a ray crosses before its end cell.
  for (const auto& h : hits) {
    traverse(sensor, h, options_.resolution_m, [&](int x, int y, bool last) {
      if (!last) update(x, y, miss);
    });
  }
}

}  // namespace fleetmap::localization
