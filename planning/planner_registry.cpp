#include "planning/planner.h"
#include "planning/planners.h"

namespace fleetmap::planning {

core::Registry<PlannerMaker>& planner_registry() {
  static core::Registry<PlannerMaker> registry("planner");
  static const bool built_in = [] {
    auto& r = registry;
    const auto ompl = [](OmplAlgorithm a) {
      return PlannerMaker{[a](const core::Params&) { return make_ompl_planner(a); }};
    };
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
          {[](const core::Params&) { return make_astar_planner(); }});
    r.add("reactive",
          "reactive steering of the map-alignment paper's sec. VII: head for the goal, turn by a fixed angle around "
          "obstacles within r_max (naive baseline)",
          {make_reactive_planner, false},
          // The map-alignment paper, sec. VII: head for the target; when an obstacle cell lies within
          // look_ahead (r_max) and within turn_angle_deg of the heading, turn by that angle away from it.
          {core::ParamSpec::number("turn_angle_deg", 10, {1e-3, 179.999}, "deg", "the turn away from an obstacle ahead"),
           core::ParamSpec::number("look_ahead", 0.5, {1e-3, 1e3}, "m", "an obstacle this close ahead makes it turn (r_max)"),
           core::ParamSpec::number("step", 0, {0, 1e3}, "m", "distance per control step (0: half a cell)"),
           core::ParamSpec::number("max_travel_factor", 4, {1e-3, 1e6}, "",
                                   "gives up after travelling this many times the map's half perimeter")});
    return true;
  }();
  (void)built_in;
  return registry;
}

void register_planner(std::string name, std::string help, PlannerMaker maker, std::vector<core::ParamSpec> params) {
  planner_registry().add(std::move(name), std::move(help), std::move(maker), std::move(params));
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

core::Params planner_options(const std::string& name, const core::Settings& settings) {
  return planner_registry().configure(name, settings);
}

std::unique_ptr<Planner> make_planner(const std::string& name, const core::Settings& settings) {
  return planner_registry().get(name).make.make(planner_options(name, settings));
}

}  // namespace fleetmap::planning
