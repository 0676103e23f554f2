// `fleetmap replay-compare A/replay.html B/replay.html --out compare.html`: two runs' replays on one
// page, at the same step on one timeline, with both coverage curves and the differences in metrics.
#include <fmt/format.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "cli/command.h"
#include "cli/outputs.h"
#include "core/error.h"
#include "io/file_io.h"
#include "viz/replay_compare.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

struct CompareOptions {
  std::vector<std::string> pages;
  std::vector<std::string> labels;
  std::string out = "compare.html";
};

// A run's label: its folder's name (replay.html sits in the run's output folder), else the file's stem.
std::vector<std::string> default_labels(const std::vector<std::string>& pages) {
  std::vector<std::string> labels;
  for (const auto& p : pages) {
    const fs::path path = fs::absolute(p).lexically_normal();
    const std::string folder = path.parent_path().filename().string();
    labels.push_back(path.filename() == "replay.html" && !folder.empty() ? folder : path.stem().string());
  }
  if (std::set<std::string>(labels.begin(), labels.end()).size() != labels.size()) {
    for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = std::string(1, char('A' + i)) + ": " + labels[i];
  }
  return labels;
}

int run_compare(const CompareOptions& o) {
  if (o.pages.size() < 2 || o.pages.size() > 4) throw InputError("replay-compare: give two to four replay pages (replay.html)");
  if (!o.labels.empty() && o.labels.size() != o.pages.size())
    throw InputError(fmt::format("--label: give one per page ({} pages, {} labels)", o.pages.size(), o.labels.size()));
  if (!io::is_standard_output(o.out) && fs::path(o.out).extension() != ".html") {
    throw InputError("--out " + io::printable(o.out) + ": the comparison is an HTML page; give a name ending in .html (or - for the standard output)");
  }
  std::vector<fs::path> inputs(o.pages.begin(), o.pages.end());
  const std::vector<OutputFile> outputs = {{"--out", o.out}};
  check_outputs(outputs, inputs);
  const std::vector<std::string> labels = o.labels.empty() ? default_labels(o.pages) : o.labels;
  std::vector<viz::ComparedReplay> runs;
  for (std::size_t i = 0; i < o.pages.size(); ++i) {
    if (!fs::is_regular_file(o.pages[i])) throw InputError(o.pages[i] + ": no such file (a replay page: fleetmap explore --html writes replay.html)");
    std::string page = io::read_file(o.pages[i]);
    // The page's own name in errors: what the user typed.
    viz::replay_page_data(page, o.pages[i]);
    runs.push_back({labels[i], std::move(page)});
  }
  const std::string html = viz::replay_comparison_html(runs);
  write_output(o.out, html);
  fmt::print(report_stream(outputs), "{}: {} runs side by side ({:.1f} MB)\n", o.out, runs.size(), double(html.size()) / 1e6);
  return 0;
}

}  // namespace

Command add_replay_compare_command(CLI::App& root) {
  auto opts = std::make_shared<CompareOptions>();
  CLI::App* app = root.add_subcommand(
      "replay-compare",
      "Two runs' replay pages side by side on one timeline (one self-contained HTML page):\n"
      "both runs at the same step with one slider, play and speed; their coverage curves on one plot\n"
      "with the difference at the step; their metrics (steps to 95%/99%, coverage, distance, events)\n"
      "with the differences; each run's why panel (the strategy's candidates and scores).\n"
      "Example: fleetmap explore --map office --robots 4 --strategy coordinated --html --out a\n"
      "         fleetmap explore --map office --robots 4 --strategy tour --html --out b\n"
      "         fleetmap replay-compare a/replay.html b/replay.html --out compare.html");
  app->add_option("pages", opts->pages, "the replay pages (replay.html of `explore --html`, or a bench's replay_*.html), two to four")
      ->required()
      ->check(CLI::ExistingFile);
  app->add_option("--label", opts->labels, "a name per page, in order (default: each page's folder name)");
  app->add_option("--out,-o", opts->out, "the comparison page to write, NAME.html, or - for the standard output (default compare.html)");
  return {app, [opts] { return run_compare(*opts); }};
}

}  // namespace fleetmap::cli
