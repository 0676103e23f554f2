#pragma once
// What `fleetmap slam` leaves behind: D'Alfonso et al.'s Table 1 (means and standard deviations over the
// runs) as Markdown and CSV, every run's numbers, the rendezvous' bytes, and pictures like
// D'Alfonso et al.'s Figs. 5-8. Every file is written to a temporary name and renamed.
#include <opencv2/core/mat.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "experiments/slam_experiment.h"

namespace fleetmap::experiments {

// Mean and sample standard deviation (0 for fewer than two values).
struct MeanStd {
  double mean = 0.0;
  double std = 0.0;
  int count = 0;
};
MeanStd mean_std(const std::vector<double>& values);

// The runs of one scenario: with exchange (the team), and the single-robot runs of
// scenario.single_robot (empty when there is none).
struct SlamCampaign {
  std::vector<SlamRunResult> team;
  std::vector<SlamRunResult> alone;
};

// Table 1 with more rows: mu (D'Alfonso et al.'s form), the standard NEES, nu (D'Alfonso et al.'s form), the mean
// distance to the walls, position RMSE, boundary covered, polynomials, tau; one column per robot
// and one for the single-robot run; D'Alfonso et al.'s printed values beside the first three robots' when
// `paper_columns` (the dalfonso scenario). Then bytes per rendezvous against the grid patch.
std::string slam_table_markdown(const SlamSetup& setup, const SlamCampaign& campaign, bool paper_columns);
// The same numbers, one row per (metric, robot, mode): metric,robot,mode,mean,std,runs.
std::string slam_table_csv(const SlamSetup& setup, const SlamCampaign& campaign);
// One row per run and robot.
std::string slam_runs_csv(const SlamCampaign& campaign);
// One row per rendezvous message.
std::string slam_rendezvous_csv(const SlamCampaign& campaign);

// A robot's result as D'Alfonso et al. draws it: mapped polynomials green, true walls red, true path blue,
// estimated path dashed red, rendezvous points; legend and scale bar.
cv::Mat render_slam_robot(const SlamSetup& setup, const SlamRunResult& run, int robot, const std::string& title);

// Writes table1.md, table1.csv, runs.csv, rendezvous.csv, map_<name>.png for each robot of the
// first team run and map_<name>_alone.png for the first single-robot run. Returns the files.
// The names write_slam_outputs gives its files for this scenario.
std::vector<std::string> slam_output_files(const SlamScenario& scenario);
std::vector<std::filesystem::path> write_slam_outputs(const SlamSetup& setup, const SlamCampaign& campaign,
                                                      const std::filesystem::path& dir, bool paper_columns);

}  // namespace fleetmap::experiments
