#pragma once
// The pyramid levels of a PreparedGrid (merging/prepared_grid.h): OpenCV images, inside the
// library (not installed), read by the merge methods and the common refine / score / decide steps.
//
// Images here have one pixel per cell with column = cell x and row = cell y (row 0 at the
// bottom, unlike a picture), so image coordinates are cell coordinates. A cell's centre is at
// integer coordinates. Masks are CV_8U with 0 / 255.
#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "merging/acceptance.h"
#include "merging/prepared_grid.h"

namespace fleetmap::merging {

// One pyramid level. Level k has cells of 2^k x 2^k fine cells; a coarse cell is occupied when
// any of its fine cells is, free when one is free and none occupied (max pooling keeps thin walls).
struct GridLevel {
  int factor = 1;              // fine cells per cell of this level, along each axis
  cv::Mat occupied;            // CV_8U mask
  cv::Mat free;                // CV_8U mask
  // CV_8U, per cell: kKnown (occupied or free), kFree, kFreeNear (a free cell in the 3 x 3 block
  // around it, cut at the level's edges). One read answers what the per-point paths ask (known,
  // free, seen from the same side) instead of one read of each mask, or nine.
  cv::Mat cells;
  static constexpr std::uint8_t kKnown = 1, kFree = 2, kFreeNear = 4;
  cv::Mat walls;               // occupied cells with a free 8-neighbour
  // CV_32F: distance in cells from each cell centre to the nearest wall cell, at most
  // PrepareOptions::max_wall_distance (that value where the walls are farther).
  cv::Mat wall_distance;
  std::vector<Eigen::Vector2f> wall_points;  // centres of the wall cells (subsampled on big maps)
  // For each wall point, the unit direction toward the free space it was seen from (zero where
  // free space lies on several sides): two maps agree on a wall only when they saw it from the
  // same side. Without it, two maps of neighbouring rooms laid edge to edge along their common
  // wall would fit as well as the right answer.
  std::vector<Eigen::Vector2f> wall_normals;
  cv::Mat free_band;           // free cells next to a wall (8-neighbourhood): the walls' seen side
  // Occupied cells of small obstacles standing alone (PrepareOptions::clutter_size_m): people,
  // chairs, what moves between two visits. They may match the other map but never contradict it.
  cv::Mat clutter;
  std::vector<std::uint8_t> wall_clutter;  // per wall point: 1 when it is clutter
  // Centres of occupied cells that are not walls (inside filled obstacles), every second row and
  // column: on the other map's clear free space they contradict an alignment too.
  std::vector<Eigen::Vector2f> interior_points;

  int width() const { return occupied.cols; }
  int height() const { return occupied.rows; }
  bool known(int x, int y) const { return (cell(x, y) & kKnown) != 0; }
  bool is_free(int x, int y) const { return (cell(x, y) & kFree) != 0; }
  std::uint8_t cell(int x, int y) const { return cells.ptr<std::uint8_t>(y)[x]; }
  // Bilinear wall distance at a continuous cell position; `outside` beyond the level's edges.
  // (Inline, like the two below: they are on the refinement's and the scores' per-point paths.)
  float distance_at(float x, float y, float outside) const {
    if (!(x >= 0.0f && y >= 0.0f && x <= float(width() - 1) && y <= float(height() - 1))) return outside;
    const Patch q = patch(x, y);
    return (1 - q.fy) * ((1 - q.fx) * q.a + q.fx * q.b) + q.fy * ((1 - q.fx) * q.c + q.fx * q.d);
  }
  // The same with the gradient of the bilinear patch (0 beyond the edges).
  float distance_gradient_at(float x, float y, float outside, float& gx, float& gy) const {
    gx = gy = 0.0f;
    if (!(x >= 0.0f && y >= 0.0f && x <= float(width() - 1) && y <= float(height() - 1))) return outside;
    const Patch q = patch(x, y);
    gx = (1 - q.fy) * (q.b - q.a) + q.fy * (q.d - q.c);
    gy = (1 - q.fx) * (q.c - q.a) + q.fx * (q.d - q.b);
    return (1 - q.fy) * ((1 - q.fx) * q.a + q.fx * q.b) + q.fy * ((1 - q.fx) * q.c + q.fx * q.d);
  }

 private:
  // The four distances around a position inside the level, a = (x0, y0), b = (x0 + 1, y0),
  // c = (x0, y0 + 1), d = (x0 + 1, y0 + 1), and the position's offsets from (x0, y0).
  struct Patch {
    float a, b, c, d, fx, fy;
  };
  Patch patch(float x, float y) const {
    const int x0 = std::min(int(x), std::max(0, width() - 2));
    const int y0 = std::min(int(y), std::max(0, height() - 2));
    const int x1 = std::min(x0 + 1, width() - 1), y1 = std::min(y0 + 1, height() - 1);
    const float* r0 = wall_distance.ptr<float>(y0);
    const float* r1 = wall_distance.ptr<float>(y1);
    return {r0[x0], r0[x1], r1[x0], r1[x1], x - float(x0), y - float(y0)};
  }
};

// The nearest cell to a continuous coordinate, or -1 when it lies before the first cell.
// (std::lround is a library call; this is on every hot path.)
inline int nearest_cell(float v) { return v >= -0.5f ? int(v + 0.5f) : -1; }
inline int nearest_cell(double v) { return v >= -0.5 ? int(v + 0.5) : -1; }

// Whether a wall point of one map, moved to `p` with its normal turned to `n`, was seen from the
// side where `target` has free space: some cell of the 3 x 3 block `distance` cells along the
// normal is free there (a block, not a cell: far beams leave unknown gaps between free rays). A
// point without a normal passes.
inline bool seen_from_same_side(const GridLevel& target, const Eigen::Vector2f& p, const Eigen::Vector2f& n,
                                float distance = 2.0f) {
  if (n.x() == 0.0f && n.y() == 0.0f) return true;
  const Eigen::Vector2f q = p + distance * n;
  const int cx = nearest_cell(q.x()), cy = nearest_cell(q.y());
  if (cx >= 0 && cy >= 0 && cx < target.width() && cy < target.height())
    return (target.cell(cx, cy) & GridLevel::kFreeNear) != 0;
  // Just outside the level, the block's cells inside it.
  for (int y = std::max(0, cy - 1); y <= std::min(target.height() - 1, cy + 1); ++y)
    for (int x = std::max(0, cx - 1); x <= std::min(target.width() - 1, cx + 1); ++x)
      if (target.is_free(x, y)) return true;
  return false;
}

// The part of `source` under `mask` (CV_8U, source's size; nonzero = kept), cut to the mask's
// box with `origin` (a multiple of the coarsest level's factor, so that every level is cut at a
// cell boundary): source's cells, walls, clutter and distance fields, masked, without preparing
// them again. Distances still count walls just outside the mask, so a mask should have a margin
// of a few cells around what matters. grid() stays source's grid (for its resolution). An empty
// mask gives a grid without walls.
PreparedGrid prepared_part(const PreparedGrid& source, const cv::Mat& mask, const PrepareOptions& options,
                           Eigen::Vector2i& origin);

// The acceptance index (merging/acceptance.h) of two prepared levels: b's known cells (a masked
// part's cells only) placed by b_to_a on a.
Acceptance acceptance_index(const GridLevel& a, const GridLevel& b, const core::Transform2& b_to_a);

}  // namespace fleetmap::merging
