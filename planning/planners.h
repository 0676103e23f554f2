#pragma once
// The factories behind the planner registry (planner_registry.cpp). Add a planner by writing its
// file, declaring its factory here and adding one row to the registry table.
#include <memory>

#include "planning/planner.h"

namespace fleetmap::planning {

// The OMPL planners; ompl_planner.cpp is the one file that includes OMPL.
enum class OmplAlgorithm { RrtStar, InformedRrtStar, PrmStar, RrtConnect, BitStar };
std::unique_ptr<Planner> make_ompl_planner(OmplAlgorithm algorithm);

std::unique_ptr<Planner> make_astar_planner();
std::unique_ptr<Planner> make_reactive_planner(const core::Params& params);

}  // namespace fleetmap::planning
