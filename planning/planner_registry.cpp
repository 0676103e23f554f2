#include <functional>

#include "core/error.h"
#include "planning/planner.h"
#include "planning/planners.h"

namespace fleetmap::planning {

namespace {

struct Entry {
  PlannerInfo info;
  std::function<std::unique_ptr<Planner>()> make;
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> kEntries = {
      {{"rrtstar", "OMPL RRT* (Karaman & Frazzoli 2011): asymptotically optimal tree; uses the whole budget"},
       [] { return make_ompl_planner(OmplAlgorithm::RrtStar); }},
      {{"informedrrtstar",
        "OMPL Informed RRT* (Gammell, Srinivasa & Barfoot 2014): RRT* sampling only where the path can improve"},
       [] { return make_ompl_planner(OmplAlgorithm::InformedRrtStar); }},
      {{"prmstar", "OMPL PRM* (Karaman & Frazzoli 2011): asymptotically optimal roadmap; uses the whole budget"},
       [] { return make_ompl_planner(OmplAlgorithm::PrmStar); }},
      {{"rrtconnect", "OMPL RRT-Connect (Kuffner & LaValle 2000): two trees; stops at the first path"},
       [] { return make_ompl_planner(OmplAlgorithm::RrtConnect); }},
      {{"bitstar", "OMPL BIT* (Gammell, Srinivasa & Barfoot 2015): batch informed trees; uses the whole budget"},
       [] { return make_ompl_planner(OmplAlgorithm::BitStar); }},
      {{"astar", "A* on the 8-connected grid with the same clearance rule, then any-angle smoothing (exact baseline)"},
       make_astar_planner},
      {{"reactive",
        "seed 001 sec. VII reactive steering: head for the goal, turn by a fixed angle around obstacles within "
        "r_max (naive baseline)",
        false},
       make_reactive_planner},
  };
  return kEntries;
}

}  // namespace

const std::vector<PlannerInfo>& planner_infos() {
  static const std::vector<PlannerInfo> kInfos = [] {
    std::vector<PlannerInfo> infos;
    for (const auto& e : registry()) infos.push_back(e.info);
    return infos;
  }();
  return kInfos;
}

std::vector<std::string> planner_names() {
  std::vector<std::string> names;
  for (const auto& e : registry()) names.push_back(e.info.name);
  return names;
}

std::string planner_help() {
  std::string s;
  for (const auto& e : registry()) s += "  " + e.info.name + ": " + e.info.description + "\n";
  return s;
}

std::unique_ptr<Planner> make_planner(const std::string& name) {
  for (const auto& e : registry()) {
    if (e.info.name == name) return e.make();
  }
  std::string names;
  for (const auto& e : registry()) names += (names.empty() ? "" : ", ") + e.info.name;
  throw InputError("unknown planner '" + name + "' (valid: " + names + ")");
}

}  // namespace fleetmap::planning
