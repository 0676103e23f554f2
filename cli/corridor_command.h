#pragma once
// CLI glue of León et al.'s corridor experiment (sim/corridor_experiment.h): `fleetmap slam` runs it
// for scenario files that say `experiment: leon_corridor` (cli/slam_command.cpp).
#include <cstdint>
#include <filesystem>
#include <optional>

namespace fleetmap::cli {

// True when the scenario file names the corridor experiment. Throws InputError for an unreadable
// file or invalid YAML, naming the file.
bool is_corridor_scenario_file(const std::filesystem::path& scenario);

// Runs the experiment of `scenario` and writes its outputs to `out`; prints a summary on stdout.
// `seed` overrides the file's. Returns the exit code.
int run_corridor_scenario(const std::filesystem::path& scenario, const std::filesystem::path& out,
                          std::optional<std::uint64_t> seed, bool quiet);

}  // namespace fleetmap::cli
