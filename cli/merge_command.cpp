// `fleetmap merge`: several robots' map images become one, with each input's transform into the
// first input's pixel grid, a confidence, and a picture.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli/command.h"
#include "cli/map_notes.h"
#include "cli/outputs.h"
#include "cli/validators.h"
#include "core/angle.h"
#include "core/error.h"
#include "core/format.h"
#include "io/file_io.h"
#include "maps/builtin_maps.h"
#include "io/map_io.h"
#include "viz/render.h"
#include "merging/fusion.h"
#include "merging/merge.h"
#include "merging/multi_merge.h"
#include "merging/rendezvous.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

constexpr const char* kConvention =
    "pixel (u, v) of an input (u = column, v = row from the top) lies at scale R(theta) (u, v) + (tx, ty) in the "
    "first input's pixel grid, R(theta) = [[cos, -sin], [sin, cos]], scale = the input's metres per cell / the first's "
    "(1 for maps of one resolution)";

// A map file with no map_server YAML: its resolution is not its own.
bool is_bare_image(const std::string& source) {
  std::error_code ec;
  const std::string ext = fs::path(source).extension().string();
  return fs::is_regular_file(source, ec) && ext != ".yaml" && ext != ".yml";
}

struct MergeCommandOptions {
  std::vector<std::string> maps;
  std::string method = "auto";
  std::string out = "merged.png";
  std::string picture;
  std::string json;
  double min_confidence = 0.5;
  std::uint64_t seed = 1;
  double resolution = 0.05;
  bool resolution_given = false;  // --resolution was on the command line
};

// An input's place in the first input's pixel grid, as the convention states it: its pixel p lies at
// scale R(theta) p + t.
struct PixelPlacement {
  core::Transform2 rigid;  // R(theta) and t
  double scale = 1.0;
};

// `cells` takes the cells of `merged` (the input seen through the first input's cells: `original`
// itself, or resampled when its resolution differs; merging::merge_maps gives its transforms so)
// into the first input's cells. A pixel (u, v) of `original` is the cell (u, H - 1 - v), whose
// centre lies s (u, H - 1 - v) + c (1, 1) in `merged`'s cells (same origin; s = its cell size / the
// first's, c = (s - 1) / 2), which is the pixel s (u, v) + o of `merged`; the rigid placement of
// `merged`'s pixels then gives s R p + (R o + t).
PixelPlacement to_first_pixels(const core::Transform2& cells, const mapping::OccupancyGrid& first,
                               const mapping::OccupancyGrid& merged, const mapping::OccupancyGrid& original) {
  const core::Transform2 rigid = merging::flip_rows(cells, first.height(), merged.height());
  const double s = original.resolution() / merged.resolution();
  const double c = (s - 1.0) / 2.0;
  const Eigen::Vector2d o(c, merged.height() - 1.0 - s * (original.height() - 1.0) - c);
  return {core::Transform2(rigid.rotation_matrix() * o + rigid.translation(), rigid.rotation()), s};
}

nlohmann::json transform_json(const std::string& map, const PixelPlacement& pixels, const merging::MergeResult& pair,
                              double confidence, const std::string& method, const std::string& via) {
  nlohmann::json j;
  j["map"] = map;
  j["merged"] = true;
  j["tx"] = pixels.rigid.translation().x();
  j["ty"] = pixels.rigid.translation().y();
  j["theta_deg"] = core::rad2deg(pixels.rigid.rotation());
  j["scale"] = pixels.scale;
  j["acceptance"] = pair.acceptance;
  j["confidence"] = confidence;
  j["method"] = method;
  j["via"] = via;
  return j;
}

// The fused map in map colours: free cells tinted by the inputs that saw them, occupied cells
// black (walls dark and clear), cells where inputs disagree in red.
uchar free_tint(double channel) { return cv::saturate_cast<uchar>(255 * 0.7 + channel * 0.3); }

viz::Color free_tint(const viz::Color& c) { return {free_tint(c.r), free_tint(c.g), free_tint(c.b)}; }

cv::Mat tinted(const merging::FusedMap& fused) {
  const auto& g = fused.grid;
  cv::Mat img(g.height(), g.width(), CV_8UC3);
  for (int y = 0; y < g.height(); ++y) {
    auto* row = img.ptr<cv::Vec3b>(g.height() - 1 - y);
    for (int x = 0; x < g.width(); ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(g.width()) + std::size_t(x);
      const auto state = g.state({x, y});
      if (state == mapping::CellState::Unknown) {
        row[x] = cv::Vec3b(205, 205, 205);
        continue;
      }
      cv::Vec3d tint(0, 0, 0);
      int n = 0;
      for (std::size_t k = 0; k < fused.inputs.size() && k < 32; ++k) {
        if (!(fused.sources[i] & (1u << k))) continue;
        const viz::Color c = viz::palette_color(fused.inputs[k]);
        tint += cv::Vec3d(c.b, c.g, c.r);
        ++n;
      }
      if (n > 0) tint /= n;
      if (state == mapping::CellState::Free) {
        row[x] = cv::Vec3b(free_tint(tint[0]), free_tint(tint[1]), free_tint(tint[2]));
      } else {
        row[x] = cv::Vec3b(0, 0, 0);
      }
      if (fused.conflicts[i]) row[x] = cv::Vec3b(40, 39, 214);
    }
  }
  return img;
}

cv::Mat picture(const merging::FusedMap& fused, const std::vector<std::string>& names) {
  viz::Overlays overlays;
  for (int input : fused.inputs) {
    overlays.legend.push_back({viz::LegendItem::Swatch, free_tint(viz::palette_color(input)),
                               std::to_string(input + 1) + ": " + fs::path(names[std::size_t(input)]).filename().string()});
  }
  if (fused.conflict_cells > 0) overlays.legend.push_back({viz::LegendItem::Swatch, {214, 39, 40}, "free vs occupied"});
  viz::RenderOptions render;
  render.title = "merged: " + std::to_string(fused.inputs.size()) + " of " + std::to_string(names.size()) + " maps";
  // The known cells and half a metre around them: a small map gives a small picture.
  render.crop_margin_m = 0.5;
  return viz::decorate(tinted(fused), fused.grid.geometry(), overlays, render);
}

int run_merge(const MergeCommandOptions& o) {
  if (o.maps.size() < 2) {
    throw InputError("merge needs at least two maps, got one: " + o.maps.front());
  }
  merging::check_merge_method(o.method);
  // --out is the picture, or a map file when its name says so (then --picture may add the picture).
  const bool out_is_map = !o.out.empty() && !io::is_standard_output(o.out) && io::is_map_file_name(o.out);
  const std::string picture_path = out_is_map ? o.picture : o.out;
  if (!o.picture.empty() && !out_is_map) {
    throw InputError("--picture " + o.picture + ": --out " + o.out +
                     " is already the picture; --picture goes with a map file as --out (.yaml or .pgm)");
  }
  std::vector<OutputFile> outputs = {{"--json", o.json}, {out_is_map ? "--picture" : "--out", picture_path}};
  if (out_is_map) {
    for (const auto& f : io::map_output_files(o.out)) outputs.push_back({"--out", f});
  }
  if (!out_is_map && !o.out.empty() && !io::is_standard_output(o.out) && fs::path(o.out).extension() != ".png") {
    throw InputError("--out " + o.out + ": give a .png picture, a map file (.yaml with a .pgm beside it, or .pgm), or -");
  }
  if (!picture_path.empty()) io::check_picture_path(picture_path, out_is_map ? "--picture" : "--out");
  std::vector<fs::path> inputs;
  for (const auto& m : o.maps) {
    for (auto& f : maps::map_source_files(m)) inputs.push_back(std::move(f));
  }
  check_outputs(outputs, inputs);
  std::FILE* report = report_stream(outputs);
  io::MapLoadOptions load;
  load.default_resolution = o.resolution;
  // A bare image has no resolution of its own: without --resolution it takes the one the other
  // maps (map_server YAML, built-in) share, so that a robot's PNG merges with its teammate's YAML.
  std::vector<std::optional<mapping::OccupancyGrid>> loaded(o.maps.size());
  std::optional<double> shared;
  std::string shared_by;
  bool one_resolution = true;
  for (std::size_t i = 0; i < o.maps.size(); ++i) {
    if (is_bare_image(o.maps[i])) continue;
    loaded[i] = maps::load_map_source(o.maps[i], load);
    const double r = loaded[i]->resolution();
    if (shared && *shared != r) one_resolution = false;
    if (!shared) shared = r, shared_by = o.maps[i];
  }
  std::string source = "the default; --resolution sets it";
  if (!o.resolution_given && shared && one_resolution) {
    load.default_resolution = *shared;
    source = "that of " + shared_by + "; --resolution sets it";
  }
  // Maps of different resolutions: each pair is aligned through the coarser map's cells
  // (merging::align_across_resolutions), and the maps are fused in the first map's cells.
  std::vector<mapping::OccupancyGrid> originals;
  for (std::size_t i = 0; i < o.maps.size(); ++i) {
    const auto& m = o.maps[i];
    originals.push_back(loaded[i] ? std::move(*loaded[i]) : maps::load_map_source(m, load));
    if (originals.back().known_count() == 0) throw InputError(m + ": every cell is unknown; there is nothing to merge");
  }
  for (const auto& m : o.maps) print_map_notes(m, load, o.resolution_given, source);  // the inputs are good
  const double r0 = originals.front().resolution();
  std::vector<mapping::OccupancyGrid> resampled;  // the maps of other resolutions in the first's cells
  resampled.reserve(originals.size());
  std::vector<const mapping::OccupancyGrid*> pointers, fused_grids;
  for (std::size_t i = 0; i < originals.size(); ++i) {
    const auto& g = originals[i];
    pointers.push_back(&g);
    if (g.resolution() == r0) {
      fused_grids.push_back(&g);
      continue;
    }
    const double count = mapping::resampled_cell_count(g, r0);
    if (count > double(load.max_cells)) {
      throw InputError(fmt::format("{}: its {} m cells seen through {}'s {} m cells would make {:.0f} cells, over the "
                                   "limit of {}; give a map of coarser cells first",
                                   o.maps[i], g.resolution(), o.maps.front(), r0, count, load.max_cells));
    }
    resampled.push_back(mapping::resample(g, r0));
    fused_grids.push_back(&resampled.back());
  }

  merging::MergeOptions options;
  options.method = o.method;
  options.min_confidence = o.min_confidence;
  options.seed = o.seed;
  const merging::MultiMergeResult merged = merging::merge_maps(pointers, options);

  // The pair that placed each input, for its acceptance.
  const auto pair_of = [&](int i, int parent) -> const merging::MergeResult& {
    for (const auto& p : merged.pairs) {
      if ((p.a == parent && p.b == i) || (p.a == i && p.b == parent)) return p.result;
    }
    throw Error("merge: no pair result for a placed map");
  };
  nlohmann::json j;
  j["convention"] = kConvention;
  j["reference"] = o.maps.front();
  j["method"] = o.method;
  j["transforms"] = nlohmann::json::array();
  int placed = 1;
  fmt::print(report, "{}: the reference (first input)\n", o.maps.front());
  if (!resampled.empty()) {
    fmt::print(report, "maps of different resolutions: each pair aligned through the coarser one's cells, fused in {}'s {} m cells\n",
               o.maps.front(), r0);
  }
  for (std::size_t i = 1; i < originals.size(); ++i) {
    const auto& name = o.maps[i];
    if (!merged.to_first[i]) {
      nlohmann::json t;
      t["map"] = name;
      t["merged"] = false;
      t["reason"] = merged.reason[i];
      std::string hint;
      if (!o.resolution_given && originals[i].resolution() != r0 && (is_bare_image(name) || is_bare_image(o.maps.front()))) {
        hint = fmt::format(" (the maps' cells are {} m and {} m, a bare image's by default: if that is wrong, give "
                           "--resolution)", r0, originals[i].resolution());
      }
      if (const int k = merged.reason_pair[i]; k >= 0) {
        // Where the contradiction is, for a refusal that names one: a user looks there first.
        const auto& p = merged.pairs[std::size_t(k)];
        const auto& g = originals[std::size_t(p.a)];
        if (p.result.refusal == merging::Refusal::WallsCross && p.result.quality.open_space_walls > 0 &&
            g.resolution() == originals[std::size_t(p.b)].resolution()) {
          const Eigen::Vector2d c = p.result.quality.open_space_at;
          const Eigen::Vector2d m = g.geometry().grid_to_world(c + Eigen::Vector2d(0.5, 0.5));
          hint += fmt::format("; the wall stands around pixel ({:.0f}, {:.0f}) of {}, at {} m", c.x(), g.height() - 1 - c.y(),
                              o.maps[std::size_t(p.a)], core::format_point(m));
          t["wall_in_open_space_px"] = {std::lround(c.x()), std::lround(g.height() - 1 - c.y())};
        }
      }
      j["transforms"].push_back(t);
      fmt::print(report, "{}: not merged: {}{}\n", name, merged.reason[i], hint);
      continue;
    }
    ++placed;
    const PixelPlacement pixels = to_first_pixels(*merged.to_first[i], originals.front(), *fused_grids[i], originals[i]);
    const int parent = merged.parent[i];
    const auto& pair = pair_of(int(i), parent);
    j["transforms"].push_back(transform_json(name, pixels, pair, merged.confidence[i], merged.method[i],
                                             o.maps[std::size_t(parent)]));
    const std::string scale = pixels.scale == 1.0 ? "" : fmt::format(", scale {:.4g}", pixels.scale);
    fmt::print(report, "{}: tx {:.2f} ty {:.2f} px, theta {:.3f} deg{}, acceptance {:.3f}, confidence {:.2f} ({}, via {})\n",
               name, pixels.rigid.translation().x(), pixels.rigid.translation().y(),
               core::rad2deg(pixels.rigid.rotation()), scale, pair.acceptance, merged.confidence[i], merged.method[i],
               o.maps[std::size_t(parent)]);
  }
  j["merged_maps"] = placed;
  j["max_loop_gap_px"] = merged.max_loop_gap;

  const merging::FusedMap fused = merging::fuse_merged(fused_grids, merged);
  j["conflict_cells"] = fused.conflict_cells;
  if (!o.json.empty()) write_output(o.json, j.dump(2) + "\n");
  if (out_is_map) io::save_map(fused.grid, o.out);
  if (!picture_path.empty()) write_picture(picture_path, picture(fused, o.maps));
  for (const auto& out : outputs) {
    if (!out.path.empty() && !io::is_standard_output(out.path)) fmt::print(report, "wrote {}\n", out.path.string());
  }
  if (placed < int(originals.size())) {
    fmt::print(stderr, "fleetmap merge: {} of {} maps merged; the others have no reliable overlap\n", placed,
               originals.size());
    return 1;
  }
  return 0;
}

}  // namespace

Command add_merge_command(CLI::App& root) {
  CLI::App* merge = root.add_subcommand("merge", "Merge map images of several robots into one map");
  merge->footer(std::string("Convention: ") + kConvention +
                ".\n\nMethods:\n" + merging::merge_method_help() +
                "\nEvery answer has a confidence in [0, 1]; below --min-confidence a map is not merged (\"no reliable\n"
                "overlap\"): a wrong merge is worse than none. More than two maps: every pair is aligned, and the most\n"
                "confident pairs chain each map to the first.\n"
                "Maps of different resolutions are aligned pair by pair through the coarser one's cells and fused in\n"
                "the first's.\n"
                "--json holds `transforms`: per input after the first, map, merged, tx, ty (pixels), theta_deg,\n"
                "scale, acceptance, confidence, method, via (the input it was aligned to); or merged: false and the\n"
                "reason.\n"
                "The picture tints each input's free cells in its own colour, walls black; red cells are free in one\n"
                "map, occupied in another; it holds the known cells and half a metre around them, with metre axes. A map file (--out merged.yaml) holds the fused map as map_server writes maps (0 occupied,\n"
                "254 free, 205 unknown), with the first map's resolution and origin: `fleetmap plan --map merged.yaml`\n"
                "plans on it in the first robot's metres. Exit codes: 0 all merged, 1 some map not merged, 2 bad input.");
  auto o = std::make_shared<MergeCommandOptions>();
  merge->add_option("maps", o->maps, "Two or more maps: PNG/PGM images or map_server YAML files (the first is the reference)")
      ->required();
  merge->add_option("--method", o->method, "Alignment method: auto, overlap or features (see below)")
      ->capture_default_str()
      ->check(one_of(merging::merge_method_names()));
  merge->add_option("--out,-o", o->out,
                    "Merged map: a picture (.png; - for the standard output) or a map file in the first map's metres "
                    "(.yaml for map_server with a .pgm beside it, or a bare .pgm) that plan and explore read")
      ->capture_default_str();
  merge->add_option("--picture", o->picture, "With a map file as --out: also write the picture here (PNG)");
  merge->add_option("--json", o->json, "Write the transforms and confidences to this JSON; - for the standard output (default: none)");
  merge->add_option("--min-confidence", o->min_confidence, "Refuse merges below this confidence")
      ->capture_default_str()
      ->check(in_range(merging::kConfidenceRange));
  merge->add_option("--seed", o->seed, "Seed of the RANSAC sampling (features)")->capture_default_str()->check(seed_number());
  CLI::Option* resolution =
      merge->add_option("--resolution", o->resolution,
                        "Metres per cell of bare images (PNG/PGM without YAML) [default: the resolution the map_server "
                        "maps among the inputs share, else 0.05]");
  resolution->check(in_range(io::kResolutionRange));
  return {merge, [o, resolution]() {
            o->resolution_given = resolution->count() > 0;
            return run_merge(*o);
          }};
}

}  // namespace fleetmap::cli
