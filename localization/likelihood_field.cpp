#include "localization/likelihood_field.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fleetmap::localization {

CellWindow window_around(const core::GridGeometry& g, const Eigen::Vector2d& centre, double radius_m) {
  const Eigen::Vector2d c = g.world_to_grid(centre);
  const double r = radius_m / g.resolution();
  CellWindow w;
  w.x0 = std::clamp(int(std::floor(c.x() - r)), 0, g.width());
  w.y0 = std::clamp(int(std::floor(c.y() - r)), 0, g.height());
  w.x1 = std::clamp(int(std::ceil(c.x() + r)) + 1, 0, g.width());
  w.y1 = std::clamp(int(std::ceil(c.y() + r)) + 1, 0, g.height());
  if (w.x1 < w.x0) w.x1 = w.x0;
  if (w.y1 < w.y0) w.y1 = w.y0;
  return w;
}

namespace {
constexpr int kLut = 1024;
}  // namespace

LikelihoodField::LikelihoodField(const core::GridGeometry& geometry, const CellWindow& window,
                                 const std::function<bool(int, int)>& occupied, const LikelihoodFieldOptions& o,
                                 const HitMean& hit_mean)
    : geometry_(geometry), window_(window), resolution_(geometry.resolution()) {
  const double norm = 1.0 / (std::sqrt(2.0 * std::numbers::pi) * o.sigma_m);
  const double uniform = o.z_rand / std::max(o.max_range_m, 1e-6);
  lut_step_ = o.max_distance_m / kLut;
  lut_.resize(kLut + 1);
  for (int i = 0; i <= kLut; ++i) {
    const double d = i * lut_step_;
    lut_[std::size_t(i)] = float(std::log(o.z_hit * norm * std::exp(-0.5 * d * d / (o.sigma_m * o.sigma_m)) + uniform));
  }
  far_ = lut_.back();
  const int w = window.width(), h = window.height();
  if (w <= 0 || h <= 0) return;
  // distanceTransform measures the distance to the nearest zero pixel: walls are 0.
  cv::Mat walls(h, w, CV_8UC1, cv::Scalar(255));
  for (int y = 0; y < h; ++y) {
    auto* row = walls.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      if (occupied(window.x0 + x, window.y0 + y)) {
        row[x] = 0;
        ++occupied_cells_;
      }
    }
  }
  if (hit_mean) {
    means_.assign(std::size_t(w) * std::size_t(h), Eigen::Vector2f::Zero());
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (walls.at<std::uint8_t>(y, x) == 0) {
          means_[std::size_t(y) * std::size_t(w) + std::size_t(x)] = hit_mean(window.x0 + x, window.y0 + y).cast<float>();
        }
      }
    }
  }
  table_.assign(std::size_t(w) * std::size_t(h), float(far_));
  nearest_.assign(std::size_t(w) * std::size_t(h), -1);
  if (occupied_cells_ == 0) return;
  cv::Mat distance, labels;
  cv::distanceTransform(walls, distance, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  std::vector<int> label_cell(std::size_t(occupied_cells_) + 1, -1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (walls.at<std::uint8_t>(y, x) == 0) label_cell[std::size_t(labels.at<int>(y, x))] = y * w + x;
    }
  }
  // A cell whose centre is farther than max_distance_m from its nearest occupied cell's box (the
  // transform's distance between centres, at most 3 % off with the 5x5 mask, less half a diagonal)
  // is far from every wall whatever that cell's hit mean: its value is far_ without computing it.
  const float far_cells = float((o.max_distance_m / resolution_ + 1.0) / 0.97);
  for (int y = 0; y < h; ++y) {
    const int* label_row = labels.ptr<int>(y);
    const float* distance_row = distance.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      nearest_[i] = label_cell[std::size_t(label_row[x])];
      if (distance_row[x] > far_cells) continue;
      table_[i] = float(log_likelihood({window.x0 + x + 0.5, window.y0 + y + 0.5}));
    }
  }
}

double LikelihoodField::log_p(double d) const {
  const double u = d / lut_step_;
  if (u >= kLut) return far_;
  const int i = int(u);
  const double f = u - i;
  return (1.0 - f) * lut_[std::size_t(i)] + f * lut_[std::size_t(i) + 1];
}

double LikelihoodField::log_likelihood(const Eigen::Vector2d& p) const {
  const int x = int(std::floor(p.x())) - window_.x0, y = int(std::floor(p.y())) - window_.y0;
  if (x < 0 || y < 0 || x >= window_.width() || y >= window_.height()) return far_;
  const int n = nearest_[std::size_t(y) * std::size_t(window_.width()) + std::size_t(x)];
  if (n < 0) return far_;
  if (!means_.empty()) return log_p((p - means_[std::size_t(n)].cast<double>()).norm() * resolution_);
  const double ox = window_.x0 + n % window_.width(), oy = window_.y0 + n / window_.width();
  const double dx = std::max({ox - p.x(), p.x() - (ox + 1.0), 0.0}), dy = std::max({oy - p.y(), p.y() - (oy + 1.0), 0.0});
  return log_p(std::hypot(dx, dy) * resolution_);
}

LikelihoodField LikelihoodField::of_grid(const mapping::OccupancyGrid& grid, const CellWindow& window,
                                         const LikelihoodFieldOptions& options) {
  return LikelihoodField(
      grid.geometry(), window,
      [&](int x, int y) { return grid.state_at(grid.geometry().index({x, y})) == mapping::CellState::Occupied; },
      options);
}

double LikelihoodField::log_likelihood_bilinear(const Eigen::Vector2d& p) const {
  // Cell values sit at cell centres.
  const double gx = p.x() - 0.5 - window_.x0, gy = p.y() - 0.5 - window_.y0;
  const int x = int(std::floor(gx)), y = int(std::floor(gy));
  const double fx = gx - x, fy = gy - y;
  const auto at = [&](int cx, int cy) -> double {
    if (cx < 0 || cy < 0 || cx >= window_.width() || cy >= window_.height()) return far_;
    return table_[std::size_t(cy) * std::size_t(window_.width()) + std::size_t(cx)];
  };
  return (1 - fy) * ((1 - fx) * at(x, y) + fx * at(x + 1, y)) + fy * ((1 - fx) * at(x, y + 1) + fx * at(x + 1, y + 1));
}

double LikelihoodField::score(const std::vector<Eigen::Vector2d>& world_points) const {
  double s = 0.0;
  for (const auto& p : world_points) s += log_likelihood(geometry_.world_to_grid(p));
  return s;
}

}  // namespace fleetmap::localization
