#include "localization/cow_grid.h"

#include <algorithm>

namespace fleetmap::localization {

CowGrid::CowGrid(const core::GridGeometry& geometry, const mapping::OccupancyGridOptions& options)
    : geometry_(geometry), options_(options) {
  // An OccupancyGrid checks the options and gives the very same float constants.
  const mapping::OccupancyGrid reference(core::GridGeometry(geometry.resolution(), 1, 1), options);
  hit_ = reference.hit_log_odds();
  miss_ = reference.miss_log_odds();
  min_ = reference.min_log_odds();
  max_ = reference.max_log_odds();
  occupied_log_odds_ = float(mapping::probability_to_log_odds(options.occupied_threshold));
  tiles_x_ = (geometry.width() + kTile - 1) / kTile;
  tiles_y_ = (geometry.height() + kTile - 1) / kTile;
  tiles_.resize(std::size_t(tiles_x_) * std::size_t(tiles_y_));
}

CowGrid CowGrid::from_occupancy_grid(const mapping::OccupancyGrid& grid) {
  CowGrid g(grid.geometry(), grid.options());
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      const float l = grid.log_odds_at(grid.geometry().index({x, y}));
      if (l != 0.0f) g.writable_tile(x, y).log_odds[std::size_t((y % kTile) * kTile + x % kTile)] = l;
    }
  }
  return g;
}

CowGrid::Tile& CowGrid::writable_tile(int x, int y) {
  auto& t = tiles_[tile_index(x, y)];
  if (!t) {
    t = std::make_shared<Tile>();
  } else if (t.use_count() > 1) {
    t = std::make_shared<Tile>(*t);  // first write through a shared tile: copy it
  }
  return *t;
}

void CowGrid::integrate_ray(const Eigen::Vector2d& from, const Eigen::Vector2d& to, bool hit) {
  const auto end_cell = geometry_.world_to_cell(to);
  mapping::traverse_segment(geometry_, from, to, [&](const core::Cell& c, double) {
    const bool is_end = end_cell && c == *end_cell;
    const float delta = is_end && hit ? hit_ : miss_;
    const float now = log_odds(c.x, c.y);
    const float next = std::clamp(now + delta, min_, max_);
    const bool record_hit = is_end && hit;
    if (next != now || record_hit) {
      Tile& tile = writable_tile(c.x, c.y);
      const std::size_t i = std::size_t((c.y % kTile) * kTile + c.x % kTile);
      tile.log_odds[i] = next;
      if (record_hit && tile.hits[i] < 60000) {
        const Eigen::Vector2d g = geometry_.world_to_grid(to);
        tile.hit_x[i] += float(g.x() - c.x);
        tile.hit_y[i] += float(g.y() - c.y);
        ++tile.hits[i];
      }
    }
    return !is_end;
  });
}

mapping::OccupancyGrid CowGrid::to_occupancy_grid() const {
  mapping::OccupancyGrid g(geometry_, options_);
  for (int ty = 0; ty < tiles_y_; ++ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const auto& t = tiles_[std::size_t(ty * tiles_x_ + tx)];
      if (!t) continue;
      for (int y = ty * kTile; y < std::min((ty + 1) * kTile, geometry_.height()); ++y) {
        for (int x = tx * kTile; x < std::min((tx + 1) * kTile, geometry_.width()); ++x) {
          const float l = t->log_odds[std::size_t((y % kTile) * kTile + x % kTile)];
          if (l != 0.0f) g.set_log_odds({x, y}, l);
        }
      }
    }
  }
  return g;
}

int CowGrid::tiles_allocated() const {
  return int(std::count_if(tiles_.begin(), tiles_.end(), [](const auto& t) { return bool(t); }));
}

void CowGrid::collect_tiles(std::unordered_set<const Tile*>& seen) const {
  for (const auto& t : tiles_)
    if (t) seen.insert(t.get());
}

}  // namespace fleetmap::localization
