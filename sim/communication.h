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
// exchanged, so that each exchange sends only what the other has not had. Robots that share a map
// frame share a grid geometry; a robot that moves to another frame is reset().
class MapExchange {
 public:
  static constexpr int kTileSize = 16;
  // Bytes per tile sent: a 4-byte tile index and one byte of quantised log-odds per cell.
  static constexpr int kTileHeaderBytes = 4;

  MapExchange(int robots, const core::GridGeometry& geometry);
  // Each robot with its own map geometry (robots in their own frames).
  explicit MapExchange(const std::vector<core::GridGeometry>& geometries);

  // Robot `robot` changed the cell with this index of its own map.
  void touched(int robot, int cell_index) {
    Tiles& t = tiles_[std::size_t(robot)];
    const int x = cell_index % t.width, y = cell_index / t.width;
    t.version[std::size_t((y / kTileSize) * t.tiles_x + x / kTileSize)] = ++clock_;
  }
  // The robot's map now has this geometry and all of it is new to everyone.
  void reset(int robot, const core::GridGeometry& geometry);

  // i and j (same geometry) send each other the tiles changed since their last exchange. A received
  // cell fills only a cell the receiver has never observed: a robot's own evidence is never
  // overwritten, repeated exchanges never count the same evidence twice, and one robot's noise
  // cannot spread over another's clean map. Returns the bytes sent in both directions.
  std::int64_t exchange(int i, mapping::OccupancyGrid& map_i, int j, mapping::OccupancyGrid& map_j);

  // `from` sends `to` what changed since they last talked, for `to` to use on its own (e.g. an
  // overlap search between maps in different frames); nothing is fused. Returns the bytes.
  std::int64_t send_without_fusing(int from, int to);

 private:
  struct Tiles {
    int width = 0, height = 0, tiles_x = 0, tiles_y = 0;
    std::vector<std::uint64_t> version;
  };
  std::vector<int> changed_tiles(int robot, std::uint64_t since) const;
  std::int64_t tile_bytes(const Tiles& t, int tile) const;
  // Sends these tiles of `from`; returns the bytes.
  std::int64_t send(int from, const mapping::OccupancyGrid& src, int to, mapping::OccupancyGrid& dst,
                    const std::vector<int>& tiles);

  std::uint64_t clock_ = 0;
  std::vector<Tiles> tiles_;                               // per robot
  std::vector<std::vector<std::uint64_t>> last_exchange_;  // [robot][robot]: clock at their last exchange
};

}  // namespace fleetmap::sim
