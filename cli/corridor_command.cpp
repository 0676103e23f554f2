#include "cli/corridor_command.h"

#include <fmt/format.h>

#include <string>

#include "cli/progress.h"
#include "core/error.h"
#include "io/file_io.h"
#include "experiments/corridor_experiment.h"
#include "experiments/corridor_output.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

bool is_corridor_scenario_file(const fs::path& scenario) {
  return experiments::is_corridor_scenario(io::read_file(scenario, std::size_t{1} << 20), scenario.string());
}

int run_corridor_scenario(const fs::path& scenario, const fs::path& out, std::optional<std::uint64_t> seed, bool quiet) {
  experiments::CorridorOptions o = experiments::parse_corridor_options(io::read_file(scenario, std::size_t{1} << 20), scenario.string());
  if (seed) o.seed = *seed;
  io::OutputFolder folder(out, "slam", experiments::corridor_output_files(o), {scenario}, "--out " + out.string());
  folder.claim();
  ProgressBar bar(!quiet);
  const experiments::CorridorResult r =
      experiments::run_corridor_experiment(o, [&](int done, int total) { bar.update(done, total, "corridor experiment"); });
  bar.finish();
  const auto written = experiments::write_corridor_outputs(r, out);
  folder.finish(io::OutputFolder::names(written));
  fmt::print("{}", experiments::corridor_table_markdown(r));
  if (!r.merges.empty()) fmt::print("Merging by detection:\n\n{}\n", experiments::detection_merge_markdown(r));
  fmt::print("{} files written to {}\n", written.size(), out.string());
  return 0;
}

}  // namespace fleetmap::cli
