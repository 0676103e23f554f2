#pragma once
// Each subcommand lives in its own file and registers itself on the top-level app.
#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace fleetmap::cli {

// A registered subcommand: its CLI11 app and what to run once the command line is parsed.
// `run` returns the process exit code; it may throw fleetmap::InputError for bad input.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command add_maps_command(CLI::App& root);
Command add_merge_command(CLI::App& root);
Command add_plan_command(CLI::App& root);
Command add_slam_command(CLI::App& root);
Command add_explore_command(CLI::App& root);
Command add_bench_command(CLI::App& root);
Command add_replay_compare_command(CLI::App& root);
Command add_plugins_command(CLI::App& root);

}  // namespace fleetmap::cli
