#include "sim/communication.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
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
    : MapExchange(std::vector<core::GridGeometry>(std::size_t(robots), g)) {}

MapExchange::MapExchange(const std::vector<core::GridGeometry>& geometries)
    : tiles_(geometries.size()),
      last_exchange_(geometries.size(), std::vector<std::uint64_t>(geometries.size(), 0)) {
  for (std::size_t i = 0; i < geometries.size(); ++i) {
    reset(int(i), geometries[i]);
    std::fill(tiles_[i].version.begin(), tiles_[i].version.end(), 0);  // empty maps: nothing to send yet
  }
}

void MapExchange::reset(int robot, const core::GridGeometry& g) {
  Tiles& t = tiles_[std::size_t(robot)];
  t.width = g.width();
  t.height = g.height();
  t.tiles_x = (g.width() + kTileSize - 1) / kTileSize;
  t.tiles_y = (g.height() + kTileSize - 1) / kTileSize;
  t.version.assign(std::size_t(t.tiles_x) * std::size_t(t.tiles_y), ++clock_);
  // In its new frame the robot has exchanged nothing with anyone yet.
  for (std::size_t k = 0; k < last_exchange_.size(); ++k) {
    last_exchange_[std::size_t(robot)][k] = last_exchange_[k][std::size_t(robot)] = 0;
  }
}

std::vector<int> MapExchange::changed_tiles(int robot, std::uint64_t since) const {
  std::vector<int> tiles;
  const auto& versions = tiles_[std::size_t(robot)].version;
  for (int t = 0; t < int(versions.size()); ++t) {
    if (versions[std::size_t(t)] > since) tiles.push_back(t);
  }
  return tiles;
}

std::int64_t MapExchange::tile_bytes(const Tiles& t, int tile) const {
  const int tx = tile % t.tiles_x, ty = tile / t.tiles_x;
  const int x1 = std::min(t.width, (tx + 1) * kTileSize), y1 = std::min(t.height, (ty + 1) * kTileSize);
  return kTileHeaderBytes + std::int64_t(x1 - tx * kTileSize) * (y1 - ty * kTileSize);
}

std::int64_t MapExchange::send(int from, const mapping::OccupancyGrid& src, int to, mapping::OccupancyGrid& dst,
                               const std::vector<int>& tiles) {
  const Tiles& t = tiles_[std::size_t(from)];
  std::int64_t bytes = 0;
  for (const int tile : tiles) {
    const int tx = tile % t.tiles_x, ty = tile / t.tiles_x;
    const int x1 = std::min(t.width, (tx + 1) * kTileSize), y1 = std::min(t.height, (ty + 1) * kTileSize);
    bytes += tile_bytes(t, tile);
    bool changed = false;
    for (int y = ty * kTileSize; y < y1; ++y) {
      for (int x = tx * kTileSize; x < x1; ++x) {
        const float ls = src.log_odds_at(y * t.width + x), ld = dst.log_odds_at(y * t.width + x);
        if (ld == 0.0f && ls != 0.0f) {
          dst.set_log_odds({x, y}, ls);
          changed = true;
        }
      }
    }
    if (changed) tiles_[std::size_t(to)].version[std::size_t(tile)] = ++clock_;
  }
  return bytes;
}

std::int64_t MapExchange::exchange(int i, mapping::OccupancyGrid& map_i, int j, mapping::OccupancyGrid& map_j) {
  if (!(map_i.geometry() == map_j.geometry())) {
    throw Error("MapExchange::exchange: robots " + std::to_string(i) + " and " + std::to_string(j) +
                " do not share a map frame");
  }
  const std::uint64_t since = last_exchange_[std::size_t(i)][std::size_t(j)];
  // Both directions are chosen before either is applied: what one just got is not echoed back, and
  // what each changed before talking is never hidden by what it receives.
  const std::vector<int> from_i = changed_tiles(i, since), from_j = changed_tiles(j, since);
  const std::int64_t bytes = send(i, map_i, j, map_j, from_i) + send(j, map_j, i, map_i, from_j);
  last_exchange_[std::size_t(i)][std::size_t(j)] = last_exchange_[std::size_t(j)][std::size_t(i)] = clock_;
  return bytes;
}

std::int64_t MapExchange::send_without_fusing(int from, int to) {
  std::uint64_t& since = last_exchange_[std::size_t(from)][std::size_t(to)];
  std::int64_t bytes = 0;
  for (const int tile : changed_tiles(from, since)) bytes += tile_bytes(tiles_[std::size_t(from)], tile);
  since = clock_;
  return bytes;
}

}  // namespace fleetmap::sim
