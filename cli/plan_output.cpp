#include "cli/plan_output.h"

#include <cmath>
#include <exception>

namespace fleetmap::cli {

std::optional<std::vector<double>> parse_numbers(const std::string& text) {
  std::vector<double> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (item.empty()) return std::nullopt;
    try {
      std::size_t n = 0;
      const double v = std::stod(item, &n);
      if (n != item.size() || !std::isfinite(v)) return std::nullopt;
      out.push_back(v);
    } catch (const std::exception&) {
      return std::nullopt;
    }
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

std::optional<std::pair<double, double>> parse_pair(const std::string& text) {
  const auto v = parse_numbers(text);
  if (!v || v->size() != 2) return std::nullopt;
  return std::pair{(*v)[0], (*v)[1]};
}

namespace {
nlohmann::json point_json(const Eigen::Vector2d& p) { return nlohmann::json::array({p.x(), p.y()}); }
}  // namespace

nlohmann::json plan_json(const planning::PlanResult& r, const PlanJsonContext& c) {
  nlohmann::json j;
  j["map"] = c.map;
  j["planner"] = r.planner;
  j["success"] = r.success();
  j["status"] = std::string(planning::to_string(r.status));
  j["detail"] = r.detail;
  j["time_s"] = r.time_s;
  j["first_solution_s"] = r.first_solution_s ? nlohmann::json(*r.first_solution_s) : nlohmann::json(nullptr);
  j["length_m"] = r.success() ? nlohmann::json(r.length_m) : nlohmann::json(nullptr);
  j["start"] = point_json(c.start);
  j["goal"] = point_json(c.goal);
  j["robot_radius_m"] = c.robot_radius_m;
  j["unknown"] = c.unknown;
  j["time_budget_s"] = c.time_budget_s;
  j["seed"] = c.seed;
  j["waypoints"] = nlohmann::json::array();
  for (const auto& p : r.path) j["waypoints"].push_back(point_json(p));
  return j;
}

}  // namespace fleetmap::cli
