#pragma once
// Cells and metres are different types; GridGeometry is the one place that converts.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>

#include "core/transform2.h"

namespace fleetmap::core {

// A grid cell: x is the column (growing with world x), y the row counted from the bottom
// (growing with world y), as in ROS map_server. Image rows run the other way.
struct Cell {
  int x = 0;
  int y = 0;

  bool operator==(const Cell&) const = default;
  Cell operator+(const Cell& o) const { return {x + o.x, y + o.y}; }
  Cell operator-(const Cell& o) const { return {x - o.x, y - o.y}; }
};

std::ostream& operator<<(std::ostream& os, const Cell& c);

// A regular grid of `width` x `height` square cells of `resolution` metres. `origin` is the pose
// of the lower-left corner of cell (0, 0) in the world, as the `origin` of a map_server YAML.
class GridGeometry {
 public:
  GridGeometry() = default;
  // Throws fleetmap::Error unless resolution > 0 and width, height >= 0.
  GridGeometry(double resolution, int width, int height, const Pose2& origin = {});

  double resolution() const { return resolution_; }
  int width() const { return width_; }
  int height() const { return height_; }
  std::int64_t cell_count() const { return std::int64_t{width_} * height_; }
  const Pose2& origin() const { return origin_; }
  double width_m() const { return width_ * resolution_; }
  double height_m() const { return height_ * resolution_; }

  bool contains(const Cell& c) const { return c.x >= 0 && c.y >= 0 && c.x < width_ && c.y < height_; }
  // Row-major index with row 0 at the bottom; only for cells inside the grid.
  int index(const Cell& c) const { return c.y * width_ + c.x; }
  Cell cell_of_index(int i) const { return {i % width_, i / width_}; }

  // The cell holding a world point, or nullopt when the point is outside the grid.
  std::optional<Cell> world_to_cell(const Eigen::Vector2d& p) const;
  // The cell a world point falls in, even outside the grid.
  Cell world_to_cell_unbounded(const Eigen::Vector2d& p) const;
  // Continuous grid coordinates of a world point, in cells: (0, 0) is the lower-left corner.
  Eigen::Vector2d world_to_grid(const Eigen::Vector2d& p) const;
  Eigen::Vector2d grid_to_world(const Eigen::Vector2d& g) const;
  Eigen::Vector2d cell_center(const Cell& c) const;

  bool operator==(const GridGeometry& o) const {
    return resolution_ == o.resolution_ && width_ == o.width_ && height_ == o.height_ && origin_ == o.origin_;
  }

 private:
  double resolution_ = 1.0;
  int width_ = 0;
  int height_ = 0;
  Pose2 origin_;
  Transform2 world_to_origin_;  // origin_.as_transform().inverse(), cached: world_to_grid is hot
};

std::ostream& operator<<(std::ostream& os, const GridGeometry& g);

}  // namespace fleetmap::core

template <>
struct std::hash<fleetmap::core::Cell> {
  std::size_t operator()(const fleetmap::core::Cell& c) const noexcept {
    return std::hash<std::int64_t>()((std::int64_t{c.x} << 32) ^ static_cast<std::uint32_t>(c.y));
  }
};
