#include "planning/planner.h"
#include "planning/planners.h"

namespace fleetmap::planning {

core::Registry<PlannerMaker>& planner_registry() {
  static core::Registry<PlannerMaker> registry("planner");
  static const bool built_in = [] {
    auto& r = registry;
    const auto ompl = [](OmplAlgorithm a) { return PlannerMaker{[a] { return make_ompl_planner(a); }}; };
    r.add("rrtstar", "OMPL RRT* (Karaman & Frazzoli 2011): asymptotically optimal tree; uses the whole budget",
          ompl(OmplAlgorithm::RrtStar));
    r.add("informedrrtstar",
          "OMPL Informed RRT* (Gammell, Srinivasa & Barfoot 2014): RRT* sampling only where the path can improve",
          ompl(OmplAlgorithm::InformedRrtStar));
    r.add("prmstar", "OMPL PRM* (Karaman & Frazzoli 2011): asymptotically optimal roadmap; uses the whole budget",
          ompl(OmplAlgorithm::PrmStar));
    r.add("rrtconnect", "OMPL RRT-Connect (Kuffner & LaValle 2000): two trees; stops at the first path",
          ompl(OmplAlgorithm::RrtConnect));
    r.add("bitstar", "OMPL BIT* (Gammell, Srinivasa & Barfoot 2015): batch informed trees; uses the whole budget",
          ompl(OmplAlgorithm::BitStar));
    r.add("astar", "A* on the 8-connected grid with the same clearance rule, then any-angle smoothing (exact baseline)",
          {make_astar_planner});
    r.add("reactive",
          "reactive steering of the map-alignment paper's sec. VII: head for the goal, turn by a fixed angle around "
          "obstacles within r_max (naive baseline)",
          {make_reactive_planner, false});
    return true;
  }();
  (void)built_in;
  return registry;
}

void register_planner(std::string name, std::string help, PlannerMaker maker) {
  planner_registry().add(std::move(name), std::move(help), std::move(maker));
}

std::vector<PlannerInfo> planner_infos() {
  std::vector<PlannerInfo> infos;
  for (const auto& name : planner_registry().names()) {
    const auto& e = planner_registry().get(name);
    infos.push_back({e.name, e.help, e.make.complete});
  }
  return infos;
}

std::vector<std::string> planner_names() { return planner_registry().names(); }

std::string planner_help() { return planner_registry().help(); }

std::unique_ptr<Planner> make_planner(const std::string& name) { return planner_registry().get(name).make.make(); }

}  // namespace fleetmap::planning
