// `fleetmap maps list | show`: the built-in maps, and a picture of any map.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "cli/command.h"
#include "cli/map_notes.h"
#include "cli/outputs.h"
#include "cli/validators.h"
#include "core/error.h"
#include "io/file_io.h"
#include "maps/builtin_maps.h"
#include "io/map_io.h"
#include "viz/render.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

struct ShowOptions {
  std::string map;
  std::string out;
  std::string title;
  double resolution = 0.05;
  bool resolution_given = false;  // --resolution was on the command line
  long long max_cells = 64'000'000;
};

int run_list() {
  fmt::print("{:<13} {:>11} {:>17} {:>11}  {}\n", "name", "cells", "metres", "free m^2", "description");
  for (const auto& info : maps::builtin_maps()) {
    const auto grid = maps::load_map_source(info.name);
    const double free_m2 = double(grid.count(mapping::CellState::Free)) * grid.resolution() * grid.resolution();
    fmt::print("{:<13} {:>11} {:>17} {:>11.1f}  {}\n", info.name, fmt::format("{}x{}", grid.width(), grid.height()),
               fmt::format("{:.1f} x {:.1f} m", grid.geometry().width_m(), grid.geometry().height_m()), free_m2,
               info.description);
  }
  fmt::print("\nFiles: {} (PNG + map_server YAML). Use a name wherever a map is asked for.\n",
             maps::builtin_maps_dir().string());
  return 0;
}

int run_show(const ShowOptions& o) {
  const fs::path out = o.out.empty() ? fs::path(fs::path(o.map).stem().string() + "_map.png") : fs::path(o.out);
  io::check_picture_path(out, "--out");
  const std::vector<OutputFile> outputs = {{"--out", out}};
  check_outputs(outputs, maps::map_source_files(o.map));
  io::MapLoadOptions load;
  load.default_resolution = o.resolution;
  load.max_cells = o.max_cells;
  const auto grid = maps::load_map_source(o.map, load);
  print_map_notes(o.map, load, o.resolution_given);
  viz::RenderOptions render;
  render.title = o.title.empty() ? fs::path(o.map).stem().string() : o.title;
  write_picture(out, viz::render_map(grid, {}, render));
  const double free_m2 = double(grid.count(mapping::CellState::Free)) * grid.resolution() * grid.resolution();
  std::FILE* report = report_stream(outputs);
  fmt::print(report, "{}: {}x{} cells, {} m/cell, {:.1f} x {:.1f} m, free {:.1f} m^2\n", o.map, grid.width(),
             grid.height(), grid.resolution(), grid.geometry().width_m(), grid.geometry().height_m(), free_m2);
  if (!io::is_standard_output(out)) fmt::print(report, "wrote {}\n", out.string());
  return 0;
}

}  // namespace

Command add_maps_command(CLI::App& root) {
  CLI::App* maps = root.add_subcommand("maps", "List the built-in maps, or draw any map to a PNG");
  maps->require_subcommand(1);
  CLI::App* list = maps->add_subcommand("list", "Print every built-in map with its size and free area");
  CLI::App* show = maps->add_subcommand("show", "Render a map (built-in name, PNG/PGM image or map_server YAML) to a PNG");
  auto o = std::make_shared<ShowOptions>();
  show->add_option("map", o->map, "Built-in map name, image file or map_server YAML")->required();
  show->add_option("--out,-o", o->out, "Output PNG, or - for the standard output (default: <map name>_map.png in the current folder)");
  show->add_option("--title", o->title, "Title in the legend panel (default: the map name)");
  CLI::Option* resolution = show->add_option("--resolution", o->resolution, "Metres per cell for a bare image without YAML")
                                 ->capture_default_str()
                                 ->check(in_range(io::kResolutionRange));
  show->add_option("--max-cells", o->max_cells, "Refuse maps with more cells than this")
      ->capture_default_str()
      ->check(in_range(kMaxCellsRange));
  return {maps, [list, show, o, resolution]() {
            if (list->parsed()) return run_list();
            o->resolution_given = resolution->count() > 0;
            if (show->parsed()) return run_show(*o);
            return 2;
          }};
}

}  // namespace fleetmap::cli
