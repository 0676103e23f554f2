#pragma once
// The likelihood-field sensor model (Thrun, Burgard & Fox, Probabilistic Robotics §6.4): a beam
// end point at distance d from the nearest occupied cell has likelihood
//   p = z_hit * N(d; 0, sigma^2) + z_rand / max_range,
// with d taken from an OpenCV distance transform of a window of a grid. The field is a table of
// log p per cell of that window; points outside the window count as far from every wall.
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "core/grid_geometry.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::localization {

struct LikelihoodFieldOptions {
  double sigma_m = 0.1;          // the spread of a beam end around the wall it hit
  double max_distance_m = 1.0;   // distances beyond count as this far
  double z_hit = 0.9;
  double z_rand = 0.1;
  double max_range_m = 8.0;      // for the z_rand term
};

// A rectangle of cells [x0, x1) x [y0, y1) of a grid.
struct CellWindow {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

// The cells of `geometry` within `radius_m` of `centre`, clipped to the grid.
CellWindow window_around(const core::GridGeometry& geometry, const Eigen::Vector2d& centre, double radius_m);

class LikelihoodField {
 public:
  LikelihoodField() = default;
  // `occupied(x, y)` tells whether a cell of `geometry` inside `window` is a wall. `hit_mean(x, y)`,
  // when given, is where in an occupied cell its beams ended on average (continuous grid
  // coordinates), as GMapping keeps it; without it distances are to the occupied cells' boxes.
  using HitMean = std::function<Eigen::Vector2d(int, int)>;
  LikelihoodField(const core::GridGeometry& geometry, const CellWindow& window,
                  const std::function<bool(int, int)>& occupied, const LikelihoodFieldOptions& options = {},
                  const HitMean& hit_mean = {});
  // The Occupied cells of an occupancy grid.
  static LikelihoodField of_grid(const mapping::OccupancyGrid& grid, const CellWindow& window,
                                 const LikelihoodFieldOptions& options = {});

  const core::GridGeometry& geometry() const { return geometry_; }
  const CellWindow& window() const { return window_; }
  int occupied_cells() const { return occupied_cells_; }
  double far_log_likelihood() const { return far_; }

  // log p of a point given in continuous grid coordinates (cells). `nearest`: the value stored for
  // the cell holding the point (fast, for the correlative search); `box`: from the exact distance of
  // the point to the box of the occupied cell nearest to that cell.
  double log_likelihood_nearest(const Eigen::Vector2d& grid_point) const {
    const int x = int(std::floor(grid_point.x())) - window_.x0, y = int(std::floor(grid_point.y())) - window_.y0;
    if (x < 0 || y < 0 || x >= window_.width() || y >= window_.height()) return far_;
    return table_[std::size_t(y) * std::size_t(window_.width()) + std::size_t(x)];
  }
  // Adds log_likelihood_nearest of the cells (x + i, y), i in [0, n), to out[i]: a row of the
  // correlative search's window, for one end point.
  void add_nearest_row(int x, int y, int n, double* out) const {
    x -= window_.x0;
    y -= window_.y0;
    const bool row_inside = y >= 0 && y < window_.height();
    const int begin = row_inside ? std::clamp(-x, 0, n) : n, end = row_inside ? std::clamp(window_.width() - x, begin, n) : n;
    for (int i = 0; i < begin; ++i) out[i] += far_;
    if (begin < end) {
      const float* row = &table_[std::size_t(y) * std::size_t(window_.width()) + std::size_t(x)];
      for (int i = begin; i < end; ++i) out[i] += row[i];
    }
    for (int i = end; i < n; ++i) out[i] += far_;
  }
  // From the exact distance of the point to the nearest occupied cell (of the cell holding it): to
  // its mean hit point, or to its box.
  double log_likelihood(const Eigen::Vector2d& grid_point) const;
  double log_likelihood_bilinear(const Eigen::Vector2d& grid_point) const;
  // The sum of log_likelihood over points given in the world frame.
  //
  // Distances are to where beams really ended (the hit means) or, without them, to the occupied
  // cells' boxes, never to the cells' centres: a beam marks the cell holding its end point,
  // anywhere in that cell (OccupancyGrid::integrate_ray), and measuring to centres pulls every new
  // end point toward them, a bias of up to half a cell that incremental mapping accumulates.
  double score(const std::vector<Eigen::Vector2d>& world_points) const;

 private:
  core::GridGeometry geometry_;
  CellWindow window_;
  double log_p(double distance_m) const;

  std::vector<float> table_;    // log p per window cell (distance to the nearest box), row-major from y0
  std::vector<int> nearest_;    // per window cell, the window index of the nearest occupied cell
  std::vector<Eigen::Vector2f> means_;  // per window cell, its hit mean (grid coordinates), if given
  std::vector<float> lut_;      // log p over [0, max_distance], kLut + 1 samples
  double lut_step_ = 1.0;       // metres per sample
  double resolution_ = 1.0;
  double far_ = 0.0;
  int occupied_cells_ = 0;
};

}  // namespace fleetmap::localization
