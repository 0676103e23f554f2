#pragma once
// Where the robots start: the scenario's list of poses (checked against the map), packed around
// the map's centre or `cluster_at`, or at random reachable places a minimum distance apart.
#include <vector>

#include "core/transform2.h"
#include "core/random.h"
#include "sim/scenario.h"
#include "sim/world.h"

namespace fleetmap::sim {

// Robot start poses for a scenario on a map (also used to check a scenario before a run). Throws
// InputError for starts in a wall, outside the map, on another robot, or when the robots cannot all
// be placed.
std::vector<core::Pose2> place_robots(const Scenario& scenario, const World& world, core::Random& rng);

}  // namespace fleetmap::sim
