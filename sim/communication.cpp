#include "sim/communication.h"

#include <algorithm>
#include <cmath>

#include "mapping/ray_cast.h"

namespace fleetmap::sim {

std::vector<std::vector<char>> communication_links(const World& world, const std::vector<core::Pose2>& truths,
                                                   const std::vector<std::vector<Detection>>& detections,
                                                   const CommunicationOptions& o) {
  const std::size_t n = truths.size();
  std::vector<std::vector<char>> links(n, std::vector<char>(n, 0));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      bool ok = false;
      if (o.range_m == 0.0) {
        const auto sees = [&](std::size_t a, std::size_t b) {
          return std::any_of(detections[a].begin(), detections[a].end(), [&](const Detection& d) { return d.other == int(b); });
        };
        ok = sees(i, j) || sees(j, i);
      } else {
        ok = (truths[i].position() - truths[j].position()).norm() <= o.range_m;
        if (ok && o.line_of_sight) ok = mapping::line_of_sight(world.truth(), truths[i].position(), truths[j].position());
      }
      links[i][j] = links[j][i] = ok;
    }
  }
  return links;
}

MapExchange::MapExchange(int robots, const core::GridGeometry& g)
    : width_(g.width()), height_(g.height()),
      tiles_x_((g.width() + kTileSize - 1) / kTileSize), tiles_y_((g.height() + kTileSize - 1) / kTileSize),
      tile_version_(std::size_t(robots), std::vector<std::uint64_t>(std::size_t(tiles_x_) * std::size_t(tiles_y_), 0)),
      last_exchange_(std::size_t(robots), std::vector<std::uint64_t>(std::size_t(robots), 0)) {}

std::vector<int> MapExchange::changed_tiles(int robot, std::uint64_t since) const {
  std::vector<int> tiles;
  const auto& versions = tile_version_[std::size_t(robot)];
  for (int t = 0; t < int(versions.size()); ++t) {
    if (versions[std::size_t(t)] > since) tiles.push_back(t);
  }
  return tiles;
}

std::int64_t MapExchange::send(int from, int to, const std::vector<int>& tiles,
                               std::vector<mapping::OccupancyGrid>& maps) {
  const auto& src = maps[std::size_t(from)];
  auto& dst = maps[std::size_t(to)];
  std::int64_t bytes = 0;
  for (const int t : tiles) {
    const int tx = t % tiles_x_, ty = t / tiles_x_;
    const int x1 = std::min(width_, (tx + 1) * kTileSize), y1 = std::min(height_, (ty + 1) * kTileSize);
    bytes += kTileHeaderBytes + std::int64_t(x1 - tx * kTileSize) * (y1 - ty * kTileSize);
    bool changed = false;
    for (int y = ty * kTileSize; y < y1; ++y) {
      for (int x = tx * kTileSize; x < x1; ++x) {
        const float ls = src.log_odds_at(y * width_ + x), ld = dst.log_odds_at(y * width_ + x);
        if (ld == 0.0f && ls != 0.0f) {
          dst.set_log_odds({x, y}, ls);
          changed = true;
        }
      }
    }
    if (changed) tile_version_[std::size_t(to)][std::size_t(t)] = ++clock_;
  }
  return bytes;
}

std::int64_t MapExchange::exchange(int i, int j, std::vector<mapping::OccupancyGrid>& maps) {
  const std::uint64_t since = last_exchange_[std::size_t(i)][std::size_t(j)];
  // Both directions are chosen before either is applied: what one just got is not echoed back, and
  // what each changed before talking is never hidden by what it receives.
  const std::vector<int> from_i = changed_tiles(i, since), from_j = changed_tiles(j, since);
  const std::int64_t bytes = send(i, j, from_i, maps) + send(j, i, from_j, maps);
  last_exchange_[std::size_t(i)][std::size_t(j)] = last_exchange_[std::size_t(j)][std::size_t(i)] = clock_;
  return bytes;
}

}  // namespace fleetmap::sim
