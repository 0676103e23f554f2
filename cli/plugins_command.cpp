// `fleetmap plugins`: every registered member of every family (the built-in ones and those a
// program added), with the parameters each declares, generated from the registries.
#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <string>

#include "cli/command.h"
#include "core/error.h"
#include "core/format.h"
#include "core/suggest.h"
#include "experiments/slam_experiment.h"
#include "exploration/strategy.h"
#include "localization/localizer.h"
#include "maps/builtin_maps.h"
#include "merging/map_aligner.h"
#include "merging/merge.h"
#include "planning/planner.h"

namespace fleetmap::cli {

namespace {

struct Family {
  std::string name;   // as --family takes it
  std::string where;  // how a user chooses a member
  std::string members;
};

std::vector<Family> families() {
  return {
      {"strategy", "explore/bench --strategy NAME; scenario exploration.strategy: {name: NAME, KEY: VALUE}; "
                   "--set strategy.KEY=VALUE; bench --vary strategy.KEY=V1,V2",
       exploration::strategy_registry().help()},
      {"localization", "explore/bench --localization NAME; scenario localization: {name: NAME, KEY: VALUE}; "
                       "--set localization.KEY=VALUE; bench --vary localization.KEY=V1,V2",
       localization::localizer_registry().help()},
      {"merging", "explore/bench --merging NAME; scenario merging: {mode: NAME, KEY: VALUE}; --set merging.KEY=VALUE; "
                  "bench --vary merging.KEY=V1,V2",
       merging::map_aligner_registry().help()},
      {"merge-method", "merge --method NAME; the overlap aligner's method (--set merging.method=NAME)",
       merging::merge_method_registry().help()},
      {"planner", "plan --planner NAME --set planner.KEY=VALUE; explore --path-planner NAME; scenario "
                  "exploration.path_planner: {name: NAME, KEY: VALUE}; --set planner.KEY=VALUE",
       planning::planner_registry().help()},
      {"slam-method", "slam scenario files' methods", experiments::slam_method_registry().help()},
      {"map", "any --map NAME", maps::map_registry().help()},
  };
}

}  // namespace

Command add_plugins_command(CLI::App& root) {
  auto* app = root.add_subcommand(
      "plugins",
      "List every strategy, localizer, map aligner, merge method, planner, SLAM method and built-in map: the built-in "
      "ones and those a program registered, each with the parameters it declares and their defaults");
  auto family = std::make_shared<std::string>();
  app->add_option("--family", *family, "Only this family (strategy, localization, merging, merge-method, planner, "
                                       "slam-method, map)");
  app->footer(
      "\nA parameter line reads `key = default (what it accepts): what it changes`. Members without parameter\n"
      "lines take their settings from scenario keys (see `fleetmap explore --help`).\n");
  return {app, [family] {
            const auto all = families();
            std::vector<std::string> names;
            for (const auto& f : all) names.push_back(f.name);
            if (!family->empty() && std::find(names.begin(), names.end(), *family) == names.end()) {
              throw InputError("--family: unknown family '" + *family + "'" + core::did_you_mean(*family, names) +
                               " (valid: " + core::join(names) + ")");
            }
            bool first = true;
            for (const auto& f : all) {
              if (!family->empty() && f.name != *family) continue;
              fmt::print("{}{} ({})\n{}", first ? "" : "\n", f.name, f.where, f.members);
              first = false;
            }
            return 0;
          }};
}

}  // namespace fleetmap::cli
