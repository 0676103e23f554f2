#pragma once
// CLI glue of the map-alignment paper's experiments (experiments/landmark_experiment.h): `fleetmap slam`
// runs them for scenario files that say `experiment: landmark_alignment` (cli/slam_command.cpp).
#include <cstdint>
#include <filesystem>
#include <optional>

namespace fleetmap::cli {

// True when the scenario file names the landmark-alignment experiment. Throws InputError for an
// unreadable file or invalid YAML, naming the file.
bool is_landmark_scenario_file(const std::filesystem::path& scenario);

// Runs every part of the experiment and writes its outputs to `out`; prints the tables on stdout.
// `runs` and `seed` override the file's. Returns the exit code.
int run_landmark_scenario(const std::filesystem::path& scenario, const std::filesystem::path& out, std::optional<int> runs,
                          std::optional<std::uint64_t> seed, int jobs, bool quiet);

}  // namespace fleetmap::cli
