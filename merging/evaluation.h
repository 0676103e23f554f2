#pragma once
// How merging is measured (DESIGN.md §5), in one place for tests and benchmarks: transform errors
// against a known truth, and pairs of crops of one map with a known relative transform.
#include <Eigen/Core>

#include <vector>

#include "core/random.h"
#include "core/transform2.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::merging {

struct TransformError {
  double rotation_deg = 0.0;       // |estimate.theta - truth.theta|, wrapped
  double translation_cells = 0.0;  // |estimate(p) - truth(p)| at the reference point p
};

// Errors of `estimate` against `truth` (both b's cells into a's cells). The translation error is
// measured where it matters, at `reference` (a point of b, e.g. the centre of the overlap): the
// translation part alone depends on where b's origin is.
TransformError transform_error(const core::Transform2& estimate, const core::Transform2& truth,
                               const Eigen::Vector2d& reference);

// The mean distance, in cells, between where `estimate` and `truth` put b's known cells: the
// error a user sees on the merged map, whatever b's origin. `estimate` may be any 2 x 3 affine map
// (a feature method may fit a similarity); 0 when b has no known cell.
double mean_displacement(const Eigen::Matrix<double, 2, 3>& estimate, const core::Transform2& truth,
                         const mapping::OccupancyGrid& b);
double mean_displacement(const core::Transform2& estimate, const core::Transform2& truth,
                         const mapping::OccupancyGrid& b);

// How CropPairOptions::overlap is measured.
enum class OverlapMeasure {
  Area,   // the windows' areas (clipped to the source)
  Known,  // the source's known cells: the cells known in both crops over the smaller crop's known cells
};

struct CropPairOptions {
  int width = 120;                 // both crops, cells
  int height = 120;
  double overlap = 0.5;            // area(A and B) / area of a crop, both clipped to the source; 0: disjoint
  double max_rotation_deg = 180.0; // b's frame is turned by uniform(-max, max)
  double min_inside = 0.9;         // each crop keeps at least this fraction of its area on the source map
  double gap = 4.0;                // cells between disjoint crops (overlap 0)
  int max_tries = 500;
  // Known: crops may reach beyond the source (unknown there); min_inside is not used, and each crop
  // must hold at least min_known of its area in known cells. Maps robots build have unknown
  // outside and between rooms, so the share of the windows' area says little about what two views
  // have in common; overlap 0 is not supported.
  OverlapMeasure measure = OverlapMeasure::Area;
  double min_known = 0.0;
};

// Two views of one map: `a` is an axis-aligned window of the source, `b` a window of the same size
// whose frame is turned and shifted, sampled from the source at the nearest cell (outside the
// source: unknown). b_to_a is the truth.
struct CropPair {
  mapping::OccupancyGrid a, b;
  core::Transform2 b_to_a;
  core::Transform2 a_to_source, b_to_source;
  double overlap = 0.0;             // achieved, as in CropPairOptions
  Eigen::Vector2d overlap_centre_b; // centre of the common area, in b's cells (or b's centre if none)
};

// Throws fleetmap::Error when the source is too small for the requested crops after max_tries.
CropPair make_crop_pair(const mapping::OccupancyGrid& source, const CropPairOptions& options, core::Random& random);

// A procedural indoor world of any size, described by shapes rather than cells, so that views of
// it (crops turned by any angle) are drawn directly at full resolution: rooms from a random binary
// space partition with doors, some slanted walls, furniture and pillars seen only by their outline
// (their inside is unknown, as a laser scanner leaves it), and optional sensor-like noise.
struct SyntheticWorldOptions {
  int width = 2000;               // cells
  int height = 2000;
  int min_room = 50;              // cells
  int max_room = 180;
  int wall_thickness = 2;
  double door_width = 16.0;
  double furniture_per_room = 1.5;
  double speckle_rate = 0.0;      // share of free cells drawn as occupied noise
  double wall_gap_rate = 0.0;     // share of wall cells missing (unknown)
};

class SyntheticWorld {
 public:
  SyntheticWorld(const SyntheticWorldOptions& options, core::Random& random);
  int width() const { return options_.width; }
  int height() const { return options_.height; }
  // The view from a frame: a width x height grid whose cell q shows the world at frame_to_world(q).
  // Noise is drawn from `random`, so two views of one place differ as two robots' maps would.
  mapping::OccupancyGrid view(const core::Transform2& frame_to_world, int width, int height, core::Random& random) const;

 private:
  SyntheticWorldOptions options_;
  std::vector<std::vector<Eigen::Vector2d>> walls_;     // polylines, drawn with the wall thickness
  std::vector<std::vector<Eigen::Vector2d>> outlines_;  // closed polygons: outline occupied, inside unknown
};

// Crop pair options for views of a SyntheticWorld; as make_crop_pair, with the world's own view.
CropPair make_world_pair(const SyntheticWorld& world, const CropPairOptions& options, core::Random& random);

// The window [x0, x0 + width) x [y0, y0 + height) of a grid as a grid of its own (outside: unknown),
// its lower-left corner at `origin`.
mapping::OccupancyGrid crop_grid(const mapping::OccupancyGrid& grid, int x0, int y0, int width, int height,
                                 const core::Pose2& origin = {});

// `grid` seen from a frame turned and shifted by `frame_to_grid`: a width x height grid whose cell q
// holds grid's nearest cell to frame_to_grid(q) (unknown outside grid).
mapping::OccupancyGrid resample_grid(const mapping::OccupancyGrid& grid, const core::Transform2& frame_to_grid,
                                     int width, int height);

}  // namespace fleetmap::merging
