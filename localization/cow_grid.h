#pragma once
// A copy-on-write occupancy grid for particle filters: the grid is cut into square tiles held by
// std::shared_ptr; copying a CowGrid copies the pointers only, and a tile is cloned on the first
// write through a grid that shares it. Tiles never written are absent (all Unknown). Particles
// resampled from one parent therefore share every tile none of them has changed since.
//
// Cell values follow mapping::OccupancyGrid exactly (same log-odds, same clamped update, same
// thresholds), so a CowGrid and an OccupancyGrid fed the same beams hold the same numbers.
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <unordered_set>
#include <vector>

#include "core/grid_geometry.h"
#include "mapping/grid_traversal.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::localization {

class CowGrid {
 public:
  static constexpr int kTile = 32;  // cells per tile side
  struct Tile {
    std::array<float, kTile * kTile> log_odds{};
    // Where the beams that hit a cell ended: sums of their offsets from the cell's corner (cells).
    std::array<float, kTile * kTile> hit_x{}, hit_y{};
    std::array<std::uint16_t, kTile * kTile> hits{};
  };

  CowGrid() = default;
  explicit CowGrid(const core::GridGeometry& geometry, const mapping::OccupancyGridOptions& options = {});

  // The cells of an occupancy grid (its geometry and options).
  static CowGrid from_occupancy_grid(const mapping::OccupancyGrid& grid);

  const core::GridGeometry& geometry() const { return geometry_; }

  float log_odds(int x, int y) const {
    const auto& t = tiles_[tile_index(x, y)];
    return t ? t->log_odds[std::size_t((y % kTile) * kTile + x % kTile)] : 0.0f;
  }
  bool occupied(int x, int y) const { return log_odds(x, y) > occupied_log_odds_; }
  // The mean end point of the beams that hit a cell (continuous grid coordinates), or its centre.
  Eigen::Vector2d hit_mean(int x, int y) const {
    const auto& t = tiles_[tile_index(x, y)];
    const std::size_t i = std::size_t((y % kTile) * kTile + x % kTile);
    if (!t || t->hits[i] == 0) return {x + 0.5, y + 0.5};
    return {x + t->hit_x[i] / t->hits[i], y + t->hit_y[i] / t->hits[i]};
  }

  // One beam, as OccupancyGrid::integrate_ray.
  void integrate_ray(const Eigen::Vector2d& from, const Eigen::Vector2d& to, bool hit);

  // The same cells as an OccupancyGrid (for pictures, exploration and metrics).
  mapping::OccupancyGrid to_occupancy_grid() const;

  // Tiles present in this grid, and the bytes they hold.
  int tiles_allocated() const;
  // Adds this grid's tiles to `seen`; with one set over many grids, counts each shared tile once.
  void collect_tiles(std::unordered_set<const Tile*>& seen) const;
  static std::size_t tile_bytes() { return sizeof(Tile); }
  std::size_t table_bytes() const { return tiles_.size() * sizeof(std::shared_ptr<Tile>); }

 private:
  std::size_t tile_index(int x, int y) const { return std::size_t((y / kTile) * tiles_x_ + x / kTile); }
  Tile& writable_tile(int x, int y);

  core::GridGeometry geometry_;
  mapping::OccupancyGridOptions options_;
  int tiles_x_ = 0, tiles_y_ = 0;
  std::vector<std::shared_ptr<Tile>> tiles_;
  float hit_ = 0, miss_ = 0, min_ = 0, max_ = 0, occupied_log_odds_ = 0;
};

}  // namespace fleetmap::localization
