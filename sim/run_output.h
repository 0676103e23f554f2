#pragma once
// A run's pictures as OpenCV images and metrics.json as a JSON value, for fleetmap's own sources
// and the CLI (not installed: sim/run_files.h is the installed face, which writes the same files).
#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "sim/run_files.h"
#include "sim/simulation.h"
#include "viz/render.h"

namespace fleetmap::sim {

// Every number of a run; all but "timing" are identical for two runs with the same inputs.
nlohmann::json metrics_json(const RunResult& result, const std::string& map_label);

// The merged map with every robot's true trajectory (solid), estimated trajectory (dashed, when
// the localization is not ideal), final pose and landmarks; legend and scale bar.
// `extra` is drawn on top (e.g. a path planned on the merged map).
cv::Mat render_merged(const RunResult& result, const std::string& map_label, const viz::Overlays& extra = {});
// Robot i's own map with its trajectory.
cv::Mat render_robot(const RunResult& result, int robot, const std::string& map_label);

// write_run_outputs (sim/run_files.h) with `extra` drawn on merged.png.
std::vector<std::filesystem::path> write_run_outputs(const RunResult& result, const std::string& map_label,
                                                     const std::filesystem::path& dir, const viz::Overlays& extra);

}  // namespace fleetmap::sim
