#pragma once
// The corridor experiment's outputs (experiments/corridor_experiment.h): León et al.'s Table I as CSV and
// Markdown, the maps over the true walls as PNG, the merging-by-detection study as CSV, Markdown
// and PNG, and every number in corridor.json. Files are written atomically.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/corridor_experiment.h"

namespace fleetmap::experiments {

// Table I: one column per method, rows length, length error, height, height error (and the final
// position error), one table per lap count.
std::string corridor_table_markdown(const CorridorResult& result);
std::string corridor_table_csv(const CorridorResult& result);
std::string detection_merge_markdown(const CorridorResult& result);
std::string detection_merge_csv(const CorridorResult& result);
nlohmann::json corridor_json(const CorridorResult& result);

// Writes every output into `dir` (created if missing); returns the paths written.
// The names write_corridor_outputs gives its files for an experiment with these options.
std::vector<std::string> corridor_output_files(const CorridorOptions& options);
std::vector<std::filesystem::path> write_corridor_outputs(const CorridorResult& result, const std::filesystem::path& dir);

}  // namespace fleetmap::experiments
