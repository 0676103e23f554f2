#pragma once
// Every picture fleetmap draws: a grid in map colours (unknown grey, free white, occupied black)
// with overlays (paths, robots, cells such as frontiers, points such as landmarks), a legend and a
// scale bar. Images are OpenCV BGR matrices; writing them is map_io's write_image.
#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "core/grid_geometry.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::viz {

struct Color {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Color&) const = default;
};

// Distinct colours for robots / inputs (Tableau 10, then repeating).
Color palette_color(int k);

struct PathOverlay {
  std::vector<Eigen::Vector2d> points;  // metres
  Color color;
  std::string label;  // empty: not in the legend
  int thickness_px = 2;
  bool dashed = false;
};

struct PoseOverlay {  // a robot: a disc with a heading tick
  core::Pose2 pose;
  double radius_m = 0.2;
  Color color;
  std::string label;
};

struct CellsOverlay {  // e.g. frontier cells, blended over the map
  std::vector<core::Cell> cells;
  Color color;
  std::string label;
  double opacity = 0.8;
};

struct PointsOverlay {  // e.g. landmarks
  std::vector<Eigen::Vector2d> points;  // metres
  Color color;
  std::string label;
  int radius_px = 3;
};

struct Overlays {
  std::vector<CellsOverlay> cells;
  std::vector<PathOverlay> paths;
  std::vector<PointsOverlay> points;
  std::vector<PoseOverlay> poses;
};

struct RenderOptions {
  int target_size_px = 800;  // small maps are scaled up by a whole factor toward this size
  int max_size_px = 4000;    // large maps are scaled down to this size
  std::string title;
  bool legend = true;        // a panel on the right: map colours and labelled overlays
  bool scale_bar = true;
};

// The grid in map colours, one pixel per cell, top row first.
cv::Mat colorize(const mapping::OccupancyGrid& grid);

// Draws overlays, legend and scale bar on `base` (one pixel per cell of `geometry`, BGR).
cv::Mat decorate(const cv::Mat& base, const core::GridGeometry& geometry, const Overlays& overlays,
                 const RenderOptions& options = {});

inline cv::Mat render_map(const mapping::OccupancyGrid& grid, const Overlays& overlays = {},
                          const RenderOptions& options = {}) {
  return decorate(colorize(grid), grid.geometry(), overlays, options);
}

}  // namespace fleetmap::viz
