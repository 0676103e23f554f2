#include "core/grid_geometry.h"

#include <cmath>
#include <ostream>
#include <string>

#include "core/error.h"

namespace fleetmap::core {

std::ostream& operator<<(std::ostream& os, const Cell& c) {
  return os << "Cell(" << c.x << ", " << c.y << ")";
}

GridGeometry::GridGeometry(double resolution, int width, int height, const Pose2& origin)
    : resolution_(resolution), width_(width), height_(height), origin_(origin),
      world_to_origin_(origin.as_transform().inverse()) {
  if (!(resolution > 0.0) || !std::isfinite(resolution)) {
    throw Error("grid resolution must be a positive number of metres per cell, got " +
                std::to_string(resolution));
  }
  if (width < 0 || height < 0) {
    throw Error("grid size must not be negative, got " + std::to_string(width) + "x" +
                std::to_string(height));
  }
}

Eigen::Vector2d GridGeometry::world_to_grid(const Eigen::Vector2d& p) const {
  return world_to_origin_.apply(p) / resolution_;
}

Eigen::Vector2d GridGeometry::grid_to_world(const Eigen::Vector2d& g) const {
  return origin_.transform(g * resolution_);
}

Cell GridGeometry::world_to_cell_unbounded(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d g = world_to_grid(p);
  return {static_cast<int>(std::floor(g.x())), static_cast<int>(std::floor(g.y()))};
}

std::optional<Cell> GridGeometry::world_to_cell(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d g = world_to_grid(p);
  if (!(g.x() >= 0.0 && g.y() >= 0.0 && g.x() < width_ && g.y() < height_)) return std::nullopt;
  const Cell c{static_cast<int>(std::floor(g.x())), static_cast<int>(std::floor(g.y()))};
  if (!contains(c)) return std::nullopt;  // rounding at the far edge
  return c;
}

Eigen::Vector2d GridGeometry::cell_center(const Cell& c) const {
  return grid_to_world(Eigen::Vector2d(c.x + 0.5, c.y + 0.5));
}

std::ostream& operator<<(std::ostream& os, const GridGeometry& g) {
  return os << "GridGeometry(" << g.width() << "x" << g.height() << " cells, " << g.resolution()
            << " m/cell, origin " << g.origin() << ")";
}

}  // namespace fleetmap::core
