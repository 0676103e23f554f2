#pragma once
// Every picture fleetmap draws: a grid in map colours (unknown grey, free white, occupied black)
// with overlays (paths, robots, cells such as frontiers, points such as landmarks), a legend and a
// scale bar. Images are OpenCV BGR matrices; writing them is io/map_image.h's write_image.
#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <optional>
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

struct PoseOverlay {  // a robot: a disc with a heading tick (a ring for a start pose)
  core::Pose2 pose;
  double radius_m = 0.2;
  Color color;
  std::string label;
  bool start = false;  // drawn as a ring: where the robot started
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

// A legend row that no single overlay gives, e.g. "start" for the rings of every robot.
struct LegendItem {
  enum Kind { Swatch, Line, Dashed, Disc, Ring, Dot } kind = Swatch;
  Color color;
  std::string label;
};

struct Overlays {
  std::vector<CellsOverlay> cells;
  std::vector<PathOverlay> paths;
  std::vector<PointsOverlay> points;
  std::vector<PoseOverlay> poses;
  std::vector<LegendItem> legend;  // after the overlays' own rows
};

struct RenderOptions {
  int target_size_px = 800;  // small maps are scaled up by a whole factor toward this size
  int max_size_px = 4000;    // large maps are scaled down to this size
  std::string title;         // above the picture, which is widened when the title needs it
  bool legend = true;        // a panel on the right: map colours and labelled overlays
  bool scale_bar = true;
  bool axes = true;          // metre ticks along the bottom and left edges of the map
  // Crop to the known cells plus this margin (metres), so a small map in a large grid gives a
  // small picture; unset: the whole grid. Either way the picture grows to hold every overlay,
  // e.g. an estimated trajectory that drifted off the grid (drawn over "outside the grid").
  std::optional<double> crop_margin_m;
  // The legend's rows for the map's own colours, before the overlays'; unset: unknown grey, free
  // white, occupied black (colorize's colours).
  std::optional<std::vector<LegendItem>> map_legend;
  // Robot discs are at least this radius, and a fraction of the picture on large maps.
  int min_marker_px = 7;
};

// A decorated picture and where the map lies in it.
struct Picture {
  cv::Mat image;
  cv::Rect map_area;          // pixels of the map (without margins, axes, title and legend)
  double px_per_cell = 1.0;
  Eigen::Vector2d grid_min;   // grid coordinates (cells) of the map area's lower-left corner
};

// The grid in map colours, one pixel per cell, top row first.
cv::Mat colorize(const mapping::OccupancyGrid& grid);

// Draws overlays, title, axes, legend and scale bar on `base` (one pixel per cell of `geometry`,
// BGR; pixels in the unknown colour count as unknown when cropping).
Picture draw_picture(const cv::Mat& base, const core::GridGeometry& geometry, const Overlays& overlays,
                     const RenderOptions& options = {});
inline cv::Mat decorate(const cv::Mat& base, const core::GridGeometry& geometry, const Overlays& overlays,
                        const RenderOptions& options = {}) {
  return draw_picture(base, geometry, overlays, options).image;
}

inline cv::Mat render_map(const mapping::OccupancyGrid& grid, const Overlays& overlays = {},
                          const RenderOptions& options = {}) {
  return decorate(colorize(grid), grid.geometry(), overlays, options);
}

}  // namespace fleetmap::viz
