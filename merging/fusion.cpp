#include "merging/fusion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "merging/grid_level.h"

namespace fleetmap::merging {

namespace {

// The cell of `grid` nearest to a continuous cell coordinate, or nullptr-like false.
bool nearest(const mapping::OccupancyGrid& grid, const Eigen::Vector2d& p, int& index) {
  const int x = nearest_cell(p.x()), y = nearest_cell(p.y());
  if (x < 0 || y < 0 || x >= grid.width() || y >= grid.height()) return false;
  index = y * grid.width() + x;
  return true;
}

}  // namespace

FusedMap fuse_grids(const std::vector<const mapping::OccupancyGrid*>& grids,
                    const std::vector<core::Transform2>& to_first) {
  if (grids.size() != to_first.size() || grids.empty()) {
    throw Error("fuse_grids: need one transform per grid and at least one grid");
  }
  const mapping::OccupancyGrid& first = *grids.front();
  // Bounds of every input's cells in the first's frame.
  double lo_x = std::numeric_limits<double>::max(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
  for (std::size_t k = 0; k < grids.size(); ++k) {
    const auto& g = *grids[k];
    for (const auto& c : {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(g.width() - 0.5, -0.5),
                          Eigen::Vector2d(-0.5, g.height() - 0.5), Eigen::Vector2d(g.width() - 0.5, g.height() - 0.5)}) {
      const Eigen::Vector2d p = to_first[k].apply(c);
      lo_x = std::min(lo_x, p.x()), lo_y = std::min(lo_y, p.y());
      hi_x = std::max(hi_x, p.x()), hi_y = std::max(hi_y, p.y());
    }
  }
  FusedMap out;
  // Cell centres lie half a cell inside the bounds.
  out.offset = {-int(std::floor(lo_x + 1.0)), -int(std::floor(lo_y + 1.0))};
  const int width = int(std::floor(hi_x)) + out.offset.x + 1;
  const int height = int(std::floor(hi_y)) + out.offset.y + 1;
  const double res = first.resolution();
  const core::Pose2 origin =
      first.geometry().origin().compose(core::Pose2(-out.offset.x * res, -out.offset.y * res, 0.0));
  out.grid = mapping::OccupancyGrid(core::GridGeometry(res, width, height, origin), first.options());
  out.sources.assign(std::size_t(width) * std::size_t(height), 0u);
  out.conflicts.assign(out.sources.size(), 0u);
  for (int k = 0; k < int(grids.size()); ++k) out.inputs.push_back(k);
  const float lo = first.min_log_odds(), hi = first.max_log_odds();

  std::vector<core::Transform2> from_first;
  for (const auto& t : to_first) from_first.push_back(t.inverse());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector2d p(x - out.offset.x, y - out.offset.y);
      float sum = 0.0f;
      bool seen_free = false, seen_occupied = false;
      std::uint32_t bits = 0;
      for (std::size_t k = 0; k < grids.size(); ++k) {
        int index = 0;
        if (!nearest(*grids[k], from_first[k].apply(p), index)) continue;
        sum += grids[k]->log_odds_at(index);  // weak evidence counts too
        const auto state = grids[k]->state_at(index);
        if (state == mapping::CellState::Unknown) continue;
        if (k < 32) bits |= 1u << k;
        seen_free = seen_free || state == mapping::CellState::Free;
        seen_occupied = seen_occupied || state == mapping::CellState::Occupied;
      }
      const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
      out.sources[i] = bits;
      if (sum != 0.0f) out.grid.set_log_odds({x, y}, std::clamp(sum, lo, hi));
      if (seen_free && seen_occupied) {
        out.conflicts[i] = 1;
        ++out.conflict_cells;
      }
    }
  }
  return out;
}

FusedMap fuse_pair(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b, const core::Transform2& b_to_a) {
  return fuse_grids({&a, &b}, {core::Transform2::identity(), b_to_a});
}

void fuse_into(mapping::OccupancyGrid& target, const mapping::OccupancyGrid& source,
               const core::Transform2& source_to_target) {
  const core::Transform2 to_source = source_to_target.inverse();
  const float lo = target.min_log_odds(), hi = target.max_log_odds();
  for (int y = 0; y < target.height(); ++y) {
    for (int x = 0; x < target.width(); ++x) {
      int index = 0;
      if (!nearest(source, to_source.apply(Eigen::Vector2d(x, y)), index)) continue;
      if (source.log_odds_at(index) == 0.0f) continue;
      target.set_log_odds({x, y}, std::clamp(target.log_odds({x, y}) + source.log_odds_at(index), lo, hi));
    }
  }
}

}  // namespace fleetmap::merging
