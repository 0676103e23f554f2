// fleetmap: the command-line program. Thin: parses flags, calls the libraries, reports.
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <exception>
#include <filesystem>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/command.h"
#include "core/error.h"
#include "core/format.h"
#include "core/memory.h"
#include "core/suggest.h"
#include "io/file_io.h"

namespace {

// Exit codes: 0 success, 1 a failure while running, 2 bad input or usage.
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;
constexpr const char* kOutOfMemory =
    "out of memory: the map, the team or the run is too large for this machine (see --max-cells and README.md, "
    "\"Outputs, reproducibility, size\")";

std::string command_path(const CLI::App* app) {
  std::string path;
  for (const CLI::App* a = app; a != nullptr; a = a->get_parent()) {
    path = a->get_name() + (path.empty() ? "" : " " + path);
  }
  return path;
}

const CLI::App* deepest_parsed(const CLI::App* app) {
  for (const CLI::App* sub : app->get_subcommands()) {
    if (sub->parsed()) return deepest_parsed(sub);
  }
  return app;
}

// A word where a command was expected; `where` is the command path that expected it.
struct UnknownCommand : std::runtime_error {
  UnknownCommand(std::string where_, const std::string& what) : std::runtime_error(what), where(std::move(where_)) {}
  std::string where;
};

// "--name", "--name=value", "-n" or "-nvalue": a token CLI11 reads as a flag (a negative number
// or "-" is a value).
bool looks_like_flag(const std::string& w) {
  const auto letter = [](char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; };
  return w.size() >= 2 && w[0] == '-' && (letter(w[1]) || (w[1] == '-' && w.size() > 2 && letter(w[2])));
}

// Every spelling of every flag of `app` ("--robots", "-h", ...).
std::vector<std::string> flag_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* o : app.get_options()) {
    for (const auto& n : o->get_lnames()) names.push_back("--" + n);
    for (const auto& n : o->get_snames()) names.push_back("-" + n);
  }
  return names;
}

// Command words and flags are checked before CLI11 parses, so that a mistake is named as typed:
// CLI11 reports an unknown command as "a subcommand is required", hands an unknown flag's value to
// a positional argument ("File does not exist: x"), and lists leftovers last to first.
void check_words_and_flags(const CLI::App& app, int argc, char** argv) {
  const CLI::App* current = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") return;  // everything after is a value
    if (looks_like_flag(word)) {
      // A long flag up to '='; a short one is its first letter (CLI11 reads "-ovalue" as -o value).
      const std::string flag = word[1] == '-' ? word.substr(0, word.find('=')) : word.substr(0, 2);
      const std::vector<std::string> names = flag_names(*current);
      if (std::find(names.begin(), names.end(), flag) == names.end()) {
        throw UnknownCommand(command_path(current), "unknown flag '" + flag + "'" + fleetmap::core::did_you_mean(flag, names) +
                                                        " (see --help)");
      }
      continue;
    }
    const auto subs = current->get_subcommands([](const CLI::App*) { return true; });
    if (subs.empty()) continue;  // a value or a positional argument
    const CLI::App* next = nullptr;
    std::vector<std::string> words;
    for (const CLI::App* s : subs) {
      if (s->get_name() == word) next = s;
      words.push_back(s->get_name());
    }
    if (next == nullptr) {
      throw UnknownCommand(command_path(current), "unknown command '" + word + "'" + fleetmap::core::did_you_mean(word, words) +
                                                      " (commands: " + fleetmap::core::join(words) + ")");
    }
    current = next;
  }
}

// CLI11 lists unexpected arguments last to first, with no hint; this names the first one the user
// typed and, for a flag, the nearest flag of the command.
std::string unexpected_argument(const CLI::App& app, int argc, char** argv) {
  const std::vector<std::string> extras = app.remaining();
  std::string first;
  for (int i = 1; i < argc && first.empty(); ++i) {
    if (std::find(extras.begin(), extras.end(), argv[i]) != extras.end()) first = argv[i];
  }
  if (first.empty() && !extras.empty()) first = extras.front();
  if (first.size() > 1 && first[0] == '-') {
    const std::string flag = first.substr(0, first.find('='));
    std::vector<std::string> flags;
    for (const CLI::Option* o : app.get_options()) {
      for (const auto& n : o->get_lnames()) flags.push_back("--" + n);
      for (const auto& n : o->get_snames()) flags.push_back("-" + n);
    }
    return "unknown flag '" + flag + "'" + fleetmap::core::did_you_mean(flag, flags);
  }
  return "unexpected argument '" + first + "'";
}

}  // namespace

int main(int argc, char** argv) {
  // Explorations and benchmarks merge and step large maps over and over (core/memory.h).
  fleetmap::core::keep_freed_memory();
  // fleetmap reports problems itself, in one line; OpenCV's own log lines would only add noise.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  namespace fm = fleetmap;
  CLI::App app{
      "fleetmap: multi-robot exploration and mapping. A team of simulated robots explores a 2D map,\n"
      "builds and merges occupancy grids, and plans paths on the result. See `fleetmap COMMAND --help`."};
  app.name("fleetmap");
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("fleetmap 0.1.0"));

  std::vector<fm::cli::Command> commands;
  commands.push_back(fm::cli::add_explore_command(app));
  commands.push_back(fm::cli::add_bench_command(app));
  commands.push_back(fm::cli::add_maps_command(app));
  commands.push_back(fm::cli::add_merge_command(app));
  commands.push_back(fm::cli::add_plan_command(app));
  commands.push_back(fm::cli::add_slam_command(app));
  commands.push_back(fm::cli::add_replay_compare_command(app));
  commands.push_back(fm::cli::add_plugins_command(app));

  try {
    check_words_and_flags(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const UnknownCommand& e) {
    fmt::print(stderr, "{}: {}\n", e.where, fm::io::printable(e.what()));
    return kExitBadInput;
  } catch (const CLI::ExtrasError&) {
    const CLI::App* where = deepest_parsed(&app);
    fmt::print(stderr, "{}: {} (see --help)\n", command_path(where), fm::io::printable(unexpected_argument(*where, argc, argv)));
    return kExitBadInput;
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "{}: {} (see --help)\n", command_path(deepest_parsed(&app)), fm::io::printable(e.what()));
    return kExitBadInput;
  }

  // Every message is one line: names from the user are shown with their control characters escaped.
  try {
    for (const auto& c : commands) {
      if (c.app->parsed()) return c.run();
    }
  } catch (const fm::InputError& e) {
    fmt::print(stderr, "fleetmap: {}\n", fm::io::printable(e.what()));
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "fleetmap: {}\n", kOutOfMemory);
    return kExitFailure;
  } catch (const cv::Exception& e) {
    if (e.code == cv::Error::StsNoMem) {
      fmt::print(stderr, "fleetmap: {}\n", kOutOfMemory);
    } else {
      fmt::print(stderr, "fleetmap: error: {}\n", fm::io::printable(e.err));
    }
    return kExitFailure;
  } catch (const std::filesystem::filesystem_error& e) {
    const std::string path = e.path1().empty() ? std::string() : e.path1().string() + ": ";
    fmt::print(stderr, "fleetmap: {}{}\n", fm::io::printable(path), e.code().message());
    return kExitFailure;
  } catch (const std::exception& e) {
    fmt::print(stderr, "fleetmap: error: {}\n", fm::io::printable(e.what()));
    return kExitFailure;
  }
  return kExitFailure;
}
