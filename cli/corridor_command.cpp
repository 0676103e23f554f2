#include "cli/corridor_command.h"

#include <fmt/format.h>

#include <string>

#include "cli/progress.h"
#include "core/error.h"
#include "core/file_io.h"
#include "sim/corridor_experiment.h"
#include "sim/corridor_output.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

bool is_corridor_scenario_file(const fs::path& scenario) {
  return sim::is_corridor_scenario(core::read_file(scenario, std::size_t{1} << 20), scenario.string());
}

int run_corridor_scenario(const fs::path& scenario, const fs::path& out, std::optional<std::uint64_t> seed, bool quiet) {
  sim::CorridorOptions o = sim::parse_corridor_options(core::read_file(scenario, std::size_t{1} << 20), scenario.string());
  if (seed) o.seed = *seed;
  core::OutputFolder folder(out, "slam", sim::corridor_output_files(o), {scenario}, "--out " + out.string());
  folder.claim();
  ProgressBar bar(!quiet);
  const sim::CorridorResult r =
      sim::run_corridor_experiment(o, [&](int done, int total) { bar.update(done, total, "corridor experiment"); });
  bar.finish();
  const auto written = sim::write_corridor_outputs(r, out);
  folder.finish(core::OutputFolder::names(written));
  fmt::print("{}", sim::corridor_table_markdown(r));
  if (!r.merges.empty()) fmt::print("Merging by detection:\n\n{}\n", sim::detection_merge_markdown(r));
  fmt::print("{} files written to {}\n", written.size(), out.string());
  return 0;
}

}  // namespace fleetmap::cli
