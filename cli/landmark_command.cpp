#include "cli/landmark_command.h"

#include <fmt/format.h>

#include <string>

#include "cli/progress.h"
#include "experiments/landmark_experiment.h"
#include "experiments/landmark_output.h"
#include "io/file_io.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

bool is_landmark_scenario_file(const fs::path& scenario) {
  return experiments::is_landmark_scenario(io::read_file(scenario, std::size_t{1} << 20), scenario.string());
}

int run_landmark_scenario(const fs::path& scenario, const fs::path& out, std::optional<int> runs,
                          std::optional<std::uint64_t> seed, int jobs, bool quiet) {
  experiments::LandmarkExperimentOptions o =
      experiments::parse_landmark_options(io::read_file(scenario, std::size_t{1} << 20), scenario.string());
  if (runs) o.runs = *runs;
  if (seed) o.seed = *seed;
  io::OutputFolder folder(out, "slam", experiments::landmark_output_files(o), {scenario}, "--out " + out.string());
  folder.claim();
  ProgressBar bar(!quiet);
  const experiments::LandmarkExperimentResult r =
      experiments::run_landmark_experiment(o, jobs, [&](int done, int total) { bar.update(done, total, "runs"); });
  bar.finish();
  const auto written = experiments::write_landmark_outputs(r, out);
  folder.finish(io::OutputFolder::names(written));
  if (quiet) {
    fmt::print("{}\n", (out / "alignment_tables.md").string());
    return 0;
  }
  fmt::print("{}", experiments::landmark_report_markdown(r));
  fmt::print("{} files written to {}\n", written.size(), out.string());
  return 0;
}

}  // namespace fleetmap::cli
