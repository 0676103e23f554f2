#pragma once
// What `fleetmap plan` and `fleetmap explore --plan-from/--plan-to` share: reading a point from
// the command line and the JSON of a planning result.
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>
#include <utility>

#include "planning/planner.h"

namespace fleetmap::cli {

// Splits "a,b" into two numbers; nullopt unless both parse completely.
std::optional<std::pair<double, double>> parse_pair(const std::string& text);
// "a,b,c": finite numbers separated by commas (no spaces); nullopt for anything else.
std::optional<std::vector<double>> parse_numbers(const std::string& text);

struct PlanJsonContext {
  std::string map;
  Eigen::Vector2d start = Eigen::Vector2d::Zero(), goal = Eigen::Vector2d::Zero();
  double robot_radius_m = 0.2;
  std::string unknown = "obstacle";
  double time_budget_s = 1.0;
  std::uint64_t seed = 1;
};

// planner, success, status, detail, times, length in metres, start, goal, settings, waypoints.
nlohmann::json plan_json(const planning::PlanResult& result, const PlanJsonContext& context);

}  // namespace fleetmap::cli
