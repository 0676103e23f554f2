#pragma once
// A probability grid for one submap of graph SLAM (Hess et al. 2016, sec. IV): each scan moves a
// cell's occupancy odds by a fixed hit or miss factor, once per scan, hits before misses, and
// clamps it. A miss factor near 1 (0.49 against a hit's 0.55) means that the many rays grazing a
// wall at a shallow angle cannot erase it, as a log-odds grid with strong misses does. The grid
// grows to hold whatever is inserted; cells are addressed by integer coordinates floor(x / res).
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "core/transform2.h"

namespace fleetmap::localization {

struct SubmapGridOptions {
  double resolution_m = 0.05;
  double hit_probability = 0.55;
  double miss_probability = 0.49;
  double min_probability = 0.1;  // also what an unknown cell reads as
  double max_probability = 0.9;
  // When > 0, the grid also keeps a likelihood field of the surfaces its scans saw (add_surface):
  // at each cell exp(-d^2 / (2 sigma^2)) for the distance d (between cell centres) to the nearest
  // surface cell, 0 beyond 3 sigma (the end-point field of Thrun et al. and GMapping, Olson's
  // rasterized table). A wall seen once reads 1 there while free and unknown space read 0, where
  // the probabilities read 0.55, 0.49 and min_probability: the contrast a sparse log needs.
  double hit_field_sigma_m = 0.0;
};

class SubmapGrid {
 public:
  explicit SubmapGrid(const SubmapGridOptions& options = {});

  double resolution() const { return options_.resolution_m; }
  const SubmapGridOptions& options() const { return options_; }
  // The cell holding a point (metres) of the grid's frame.
  Eigen::Vector2i cell_of(const Eigen::Vector2d& p) const;
  // Probability of occupancy; unknown cells and cells outside read min_probability.
  float probability(int x, int y) const {
    const int ix = x - min_x_, iy = y - min_y_;
    if (ix < 0 || iy < 0 || ix >= width_ || iy >= height_) return float(options_.min_probability);
    const float p = cells_[std::size_t(iy) * std::size_t(width_) + std::size_t(ix)];
    return p == 0.0f ? float(options_.min_probability) : p;
  }
  bool known(int x, int y) const;
  // The surface field (options' hit_field_sigma_m) at a cell, in [0, 1]; 0 without a field,
  // outside the grid, and once the insertion state is released.
  float hit_field(int x, int y) const {
    const int ix = x - min_x_, iy = y - min_y_;
    if (field_.empty() || ix < 0 || iy < 0 || ix >= width_ || iy >= height_) return 0.0f;
    return field_[std::size_t(iy) * std::size_t(width_) + std::size_t(ix)];
  }

  // One scan taken at `sensor` (grid frame): `hits` are returns (grid frame); each cell between
  // the sensor and a hit gets a miss, each hit cell a hit, every cell at most one update.
  void insert(const Eigen::Vector2d& sensor, const std::vector<Eigen::Vector2d>& hits);
  // Adds the segment from `a` to `b` (grid frame; a point when they are equal), a piece of a
  // surface a scan inserted before saw, to the surface field: every cell the segment crosses
  // raises the field around it. The field only rises: a surface seen stays for the submap's life.
  // Nothing without a field; the segment must lie in the cells held (insert grows them).
  void add_surface(const Eigen::Vector2d& a, const Eigen::Vector2d& b);
  // Frees what only insertion needs, the surface field too (a finished submap takes no more
  // scans; one that does gets the stamps back, not the field).
  void release_insertion_state();

  // The bounds of the cells held (inclusive min, exclusive max).
  int min_x() const { return min_x_; }
  int min_y() const { return min_y_; }
  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t known_cells() const { return known_; }

 private:
  void grow_to(int lo_x, int lo_y, int hi_x, int hi_y);
  void update(int x, int y, double odds_factor);

  SubmapGridOptions options_;
  int min_x_ = 0, min_y_ = 0, width_ = 0, height_ = 0;
  std::vector<float> cells_;          // probability, 0 = unknown
  std::vector<std::uint32_t> stamp_;  // the scan that last updated the cell
  std::uint32_t scan_ = 0;
  std::size_t known_ = 0;
  std::vector<float> field_;  // the surface field, laid out as cells_ (empty: none)
  struct KernelCell {
    int dx, dy;
    float value;
  };
  std::vector<KernelCell> kernel_;  // the field around a surface cell, within 3 sigma
};

}  // namespace fleetmap::localization
