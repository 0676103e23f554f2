#pragma once
// The map-alignment paper's experiments (experiments/landmark_experiment.h) as a report: Tables I-III,
// Fig. 2 and the leader/follower merges in Markdown with the paper's values beside the measured
// ones, every rendezvous report as CSV, Fig. 2 and the global maps as PNG. Files are written
// atomically.
#include <filesystem>
#include <string>
#include <vector>

#include "experiments/landmark_experiment.h"

namespace fleetmap::experiments {

std::string landmark_report_markdown(const LandmarkExperimentResult& result);
std::string landmark_reports_csv(const LandmarkExperimentResult& result);
std::string landmark_noise_csv(const LandmarkExperimentResult& result);

// The names write_landmark_outputs gives its files for these options.
std::vector<std::string> landmark_output_files(const LandmarkExperimentOptions& options);
// Writes every output into `dir`; returns the paths written.
std::vector<std::filesystem::path> write_landmark_outputs(const LandmarkExperimentResult& result,
                                                          const std::filesystem::path& dir);

}  // namespace fleetmap::experiments
