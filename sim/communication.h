#pragma once
// Who can talk, and what robots send each other: the map cells that changed since they last
// talked, in square tiles, counted in bytes as sent.
#include <cstdint>
#include <limits>
#include <vector>

#include "core/transform2.h"
#include "mapping/occupancy_grid.h"
#include "sim/sensors.h"
#include "sim/world.h"

namespace fleetmap::sim {

struct CommunicationOptions {
  // Metres. 0: only robots that detect each other talk (rendezvous); inf: always.
  double range_m = std::numeric_limits<double>::infinity();
  bool line_of_sight = false;  // a wall between two robots cuts the link
};

// links[i][j] (symmetric): robots i and j can exchange data this step.
std::vector<std::vector<char>> communication_links(const World& world, const std::vector<core::Pose2>& truths,
                                                   const std::vector<std::vector<Detection>>& detections,
                                                   const CommunicationOptions& options);

// Keeps, per robot, when each tile of its map last changed, and per pair of robots when they last
// exchanged, so that each exchange sends only what the other has not had.
class MapExchange {
 public:
  static constexpr int kTileSize = 16;
  // Bytes per tile sent: a 4-byte tile index and one byte of quantised log-odds per cell.
  static constexpr int kTileHeaderBytes = 4;

  MapExchange(int robots, const core::GridGeometry& geometry);

  // Robot `robot` changed the cell with this index of its own map.
  void touched(int robot, int cell_index) { tile_version_[std::size_t(robot)][std::size_t(tile_of(cell_index))] = ++clock_; }

  // i and j send each other the tiles changed since their last exchange. A received cell fills only
  // a cell the receiver has never observed: a robot's own evidence is never overwritten, repeated
  // exchanges never count the same evidence twice, and one robot's noise cannot spread over
  // another's clean map. Returns the bytes sent in both directions.
  std::int64_t exchange(int i, int j, std::vector<mapping::OccupancyGrid>& maps);

 private:
  int tile_of(int cell_index) const {
    const int x = cell_index % width_, y = cell_index / width_;
    return (y / kTileSize) * tiles_x_ + x / kTileSize;
  }
  std::vector<int> changed_tiles(int robot, std::uint64_t since) const;
  // Sends these tiles of `from`; returns the bytes.
  std::int64_t send(int from, int to, const std::vector<int>& tiles, std::vector<mapping::OccupancyGrid>& maps);

  int width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  std::uint64_t clock_ = 0;
  std::vector<std::vector<std::uint64_t>> tile_version_;  // [robot][tile]
  std::vector<std::vector<std::uint64_t>> last_exchange_;  // [robot][robot]: clock at their last exchange
};

}  // namespace fleetmap::sim
