// `fleetmap merge`: several robots' map images become one, with each input's transform into the
// first input's map frame (metres and degrees; pixels besides), a confidence, and a picture.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
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
    "a point p (metres) of an input's map frame lies at R(theta) p + (tx_m, ty_m) in the first input's map frame, "
    "R(theta) = [[cos, -sin], [sin, cos]], theta in degrees counter-clockwise; a map frame is the one its map_server "
    "YAML's origin defines (a bare image's lower-left corner is (0, 0))";
constexpr const char* kPixelConvention =
    "pixel (u, v) of an input (u = column, v = row from the top) lies at scale R(theta_px) (u, v) + (tx_px, ty_px) in "
    "the first input's pixel grid, scale = the input's metres per cell / the first's (1 for maps of one resolution)";

// A map file with no map_server YAML: its resolution is not its own.
bool is_bare_image(const std::string& source) {
  std::error_code ec;
  const std::string ext = fs::path(source).extension().string();
  return fs::is_regular_file(source, ec) && ext != ".yaml" && ext != ".yml";
}

struct MergeCommandOptions {
  std::vector<std::string> maps;
  std::string method = "auto";
  std::vector<std::string> set;  // --set METHOD.KEY=VALUE
  std::string out = "merged.png";
  std::string picture;
  std::string json;
  double min_confidence = 0.5;
  std::uint64_t seed = 1;
  double resolution = 0.05;
  bool resolution_given = false;  // --resolution was on the command line
};

nlohmann::json transform_json(const std::string& map, const merging::Placement& place, const merging::MergeResult& pair,
                              double confidence, const std::string& method, const std::string& via,
                              const std::optional<merging::Uncertainty>& uncertainty) {
  nlohmann::json j;
  j["map"] = map;
  j["merged"] = true;
  j["tx_m"] = place.metres.translation().x();
  j["ty_m"] = place.metres.translation().y();
  j["theta_deg"] = core::rad2deg(place.metres.rotation());
  j["tx_px"] = place.pixels.translation().x();
  j["ty_px"] = place.pixels.translation().y();
  j["theta_px_deg"] = core::rad2deg(place.pixels.rotation());
  j["scale"] = place.scale;
  j["acceptance"] = pair.acceptance;
  j["confidence"] = confidence;
  j["method"] = method;
  j["via"] = via;
  if (place.covariance && uncertainty) {
    nlohmann::json c = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) c.push_back({(*place.covariance)(r, 0), (*place.covariance)(r, 1), (*place.covariance)(r, 2)});
    j["covariance"] = c;
    j["std_tx_m"] = uncertainty->std_tx;
    j["std_ty_m"] = uncertainty->std_ty;
    j["std_theta_deg"] = uncertainty->std_theta_deg;
    j["overlap_centre_m"] = {uncertainty->at.x(), uncertainty->at.y()};
    j["std_major_m"] = uncertainty->std_major;
    j["std_minor_m"] = uncertainty->std_minor;
    j["major_direction_deg"] = uncertainty->major_deg;
  }
  return j;
}

// The fused map in map colours: free cells in the tint of the one input that saw them, or white
// when several did; occupied cells black (walls dark and clear), cells where inputs disagree in red.
uchar free_tint(double channel) { return cv::saturate_cast<uchar>(255 * 0.7 + channel * 0.3); }

viz::Color free_tint(const viz::Color& c) { return {free_tint(c.r), free_tint(c.g), free_tint(c.b)}; }

constexpr viz::Color kSharedFree{255, 255, 255}, kUnknown{205, 205, 205}, kOccupied{0, 0, 0}, kConflict{214, 39, 40};

cv::Vec3b bgr(const viz::Color& c) { return {c.b, c.g, c.r}; }

cv::Mat tinted(const merging::FusedMap& fused) {
  const auto& g = fused.grid;
  cv::Mat img(g.height(), g.width(), CV_8UC3);
  for (int y = 0; y < g.height(); ++y) {
    auto* row = img.ptr<cv::Vec3b>(g.height() - 1 - y);
    for (int x = 0; x < g.width(); ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(g.width()) + std::size_t(x);
      const auto state = g.state({x, y});
      if (fused.conflicts[i]) {
        row[x] = bgr(kConflict);
      } else if (state == mapping::CellState::Unknown) {
        row[x] = bgr(kUnknown);
      } else if (state == mapping::CellState::Occupied) {
        row[x] = bgr(kOccupied);
      } else {
        const std::uint32_t bits = fused.sources[i];
        const bool one = bits != 0 && (bits & (bits - 1)) == 0;
        row[x] = one ? bgr(free_tint(viz::palette_color(fused.inputs[std::size_t(std::countr_zero(bits))]))) : bgr(kSharedFree);
      }
    }
  }
  return img;
}

cv::Mat picture(const merging::FusedMap& fused, const std::vector<std::string>& names) {
  viz::Overlays overlays;
  viz::RenderOptions render;
  render.map_legend = {{viz::LegendItem::Swatch, kUnknown, "unknown"},
                       {viz::LegendItem::Swatch, kSharedFree, "free in several maps"},
                       {viz::LegendItem::Swatch, kOccupied, "occupied"}};
  for (int input : fused.inputs) {
    overlays.legend.push_back({viz::LegendItem::Swatch, free_tint(viz::palette_color(input)),
                               std::to_string(input + 1) + ": " + fs::path(names[std::size_t(input)]).filename().string()});
  }
  if (fused.conflict_cells > 0) overlays.legend.push_back({viz::LegendItem::Swatch, kConflict, "free vs occupied"});
  render.title = "merged: " + std::to_string(fused.inputs.size()) + " of " + std::to_string(names.size()) + " maps";
  // The known cells and the margin of the map file: a small map gives a small picture.
  render.crop_margin_m = merging::kMergedMarginM;
  return viz::decorate(tinted(fused), fused.grid.geometry(), overlays, render);
}

int run_merge(const MergeCommandOptions& o) {
  if (o.maps.size() < 2) {
    throw InputError("merge needs at least two maps, got one: " + o.maps.front());
  }
  merging::MergeMethodSettings method_settings;
  for (const auto& text : o.set) {
    const auto a = core::parse_param_assignment(text, "--set " + text);
    auto it = std::find_if(method_settings.begin(), method_settings.end(), [&](const auto& m) { return m.first == a.family; });
    if (it == method_settings.end()) it = method_settings.insert(method_settings.end(), {a.family, {}});
    it->second.emplace_back(a.key, a.value);
    try {
      merging::check_merge_method(o.method, method_settings);
    } catch (const InputError& e) {
      throw InputError("--set " + text + ": " + e.what());
    }
  }
  merging::check_merge_method(o.method, method_settings);
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
  bool resolutions_differ = false;
  std::vector<const mapping::OccupancyGrid*> pointers;
  for (std::size_t i = 0; i < originals.size(); ++i) {
    const auto& g = originals[i];
    pointers.push_back(&g);
    if (g.resolution() == r0) continue;
    resolutions_differ = true;
    const double count = mapping::resampled_cell_count(g, r0);
    if (count > double(load.max_cells)) {
      throw InputError(fmt::format("{}: its {} m cells seen through {}'s {} m cells would make {:.0f} cells, over the "
                                   "limit of {}; give a map of coarser cells first",
                                   o.maps[i], g.resolution(), o.maps.front(), r0, count, load.max_cells));
    }
  }

  merging::MergeOptions options;
  options.method = o.method;
  options.method_settings = method_settings;
  options.min_confidence = o.min_confidence;
  options.seed = o.seed;
  const merging::MergedMaps result = merging::merge_and_fuse(pointers, options);
  const merging::MultiMergeResult& merged = result.merge;

  // The pair that placed each input, for its acceptance.
  const auto pair_of = [&](int i, int parent) -> const merging::MergeResult& {
    for (const auto& p : merged.pairs) {
      if ((p.a == parent && p.b == i) || (p.a == i && p.b == parent)) return p.result;
    }
    throw Error("merge: no pair result for a placed map");
  };
  nlohmann::json j;
  j["convention"] = kConvention;
  j["pixel_convention"] = kPixelConvention;
  j["reference"] = o.maps.front();
  j["method"] = o.method;
  if (!method_settings.empty()) {
    auto& p = j["method_parameters"];
    for (const auto& [method, settings] : method_settings) {
      const core::Params values = merging::merge_method_registry().configure(method, settings);
      for (const auto& key : values.changed()) p[method][key] = values.value_text(key);
    }
  }
  j["transforms"] = nlohmann::json::array();
  int placed = 1;
  fmt::print(report, "{}: the reference (first input)\n", o.maps.front());
  if (resolutions_differ) {
    fmt::print(report, "maps of different resolutions: each pair aligned through the coarser one's cells, fused in {}'s {} m cells\n",
               o.maps.front(), r0);
  }
  for (std::size_t i = 1; i < originals.size(); ++i) {
    const auto& name = o.maps[i];
    if (!result.placements[i]) {
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
    const merging::Placement& place = *result.placements[i];
    const int parent = merged.parent[i];
    const auto& pair = pair_of(int(i), parent);
    // Where the pair's walls met (its a's cells), in the first map's metres.
    std::optional<merging::Uncertainty> uncertainty;
    const auto pair_a = [&] {
      for (const auto& p : merged.pairs)
        if ((p.a == parent && p.b == int(i)) || (p.a == int(i) && p.b == parent)) return p.a;
      return parent;
    }();
    if (place.covariance && merged.to_first[std::size_t(pair_a)]) {
      const Eigen::Vector2d centre = merged.to_first[std::size_t(pair_a)]->apply(pair.quality.overlap_centre);
      const Eigen::Vector2d at = originals.front().geometry().grid_to_world(centre + Eigen::Vector2d(0.5, 0.5));
      uncertainty = merging::describe_uncertainty(*place.covariance, place.metres, at);
    }
    j["transforms"].push_back(transform_json(name, place, pair, merged.confidence[i], merged.method[i],
                                             o.maps[std::size_t(parent)], uncertainty));
    const std::string scale = place.scale == 1.0 ? "" : fmt::format(", scale {:.4g}", place.scale);
    fmt::print(report,
               "{}: tx {:.3f} ty {:.3f} m, theta {:.3f} deg (pixels: tx {:.2f} ty {:.2f}, theta {:.3f} deg{}), "
               "acceptance {:.3f}, confidence {:.2f} ({}, via {})\n",
               name, place.metres.translation().x(), place.metres.translation().y(),
               core::rad2deg(place.metres.rotation()), place.pixels.translation().x(), place.pixels.translation().y(),
               core::rad2deg(place.pixels.rotation()), scale, pair.acceptance, merged.confidence[i], merged.method[i],
               o.maps[std::size_t(parent)]);
    if (uncertainty) {
      fmt::print(report,
                 "  uncertainty (1 sigma, from the fit of the walls): tx {:.3f} m, ty {:.3f} m, theta {:.3f} deg; where the "
                 "maps overlap ({:.2f}, {:.2f} m): {:.3f} m along {:.0f} deg, {:.3f} m across\n",
                 uncertainty->std_tx, uncertainty->std_ty, uncertainty->std_theta_deg, uncertainty->at.x(),
                 uncertainty->at.y(), uncertainty->std_major, uncertainty->major_deg, uncertainty->std_minor);
    }
  }
  j["merged_maps"] = placed;
  j["max_loop_gap_px"] = merged.max_loop_gap;
  j["conflict_cells"] = result.fused.conflict_cells;
  if (!o.json.empty()) write_output(o.json, j.dump(2) + "\n");
  if (out_is_map) io::save_map(result.map, o.out);
  if (!picture_path.empty()) write_picture(picture_path, picture(result.fused, o.maps));
  for (const auto& out : outputs) {
    if (!out.path.empty() && !io::is_standard_output(out.path)) fmt::print(report, "wrote {}\n", out.path.string());
  }
  if (placed < int(originals.size())) {
    const std::size_t left = originals.size() - std::size_t(placed);
    fmt::print(stderr, "fleetmap merge: {} of {} maps merged (the first is the reference); {} not merged: no reliable overlap\n",
               placed, originals.size(), left == 1 ? std::string("1 map") : std::to_string(left) + " maps");
    return 1;
  }
  return 0;
}

}  // namespace

Command add_merge_command(CLI::App& root) {
  CLI::App* merge = root.add_subcommand("merge", "Merge map images of several robots into one map");
  merge->footer(std::string("Transforms: ") + kConvention + ". Pixels, for images: " + kPixelConvention +
                ".\n\nMethods:\n" + merging::merge_method_help() +
                "\nEvery answer has a confidence in [0, 1]; below --min-confidence a map is not merged (\"no reliable\n"
                "overlap\"): a wrong merge is worse than none. More than two maps: every pair is aligned, and the most\n"
                "confident pairs chain each map to the first.\n"
                "Maps of different resolutions are aligned pair by pair through the coarser one's cells and fused in\n"
                "the first's.\n"
                "--json holds `transforms`: per input after the first, map, merged, tx_m, ty_m, theta_deg (metres and\n"
                "degrees), tx_px, ty_px, theta_px_deg, scale (pixels), acceptance, confidence, method, via (the input it\n"
                "was aligned to), covariance (3 x 3, of tx_m, ty_m, theta in m, m, rad, from the fit of the walls), std_tx_m,\n"
                "std_ty_m, std_theta_deg, and where the maps overlap (overlap_centre_m) std_major_m along\n"
                "major_direction_deg and std_minor_m across; or merged: false and the reason.\n"
                "The picture shows free cells in the tint of the one input that saw them, or white when several did;\n"
                "walls black, unknown grey; red cells are free in one map, occupied in another; it holds the known cells\n"
                "and half a metre around them, with metre axes. A map file (--out merged.yaml) holds the fused map as\n"
                "map_server writes maps (0 occupied, 254 free, 205 unknown) in the first map's frame and resolution, cut\n"
                "to the known cells and half a metre around them (its origin says where): `fleetmap plan --map\n"
                "merged.yaml` plans on it in the first robot's metres. Exit codes: 0 all merged, 1 some map not merged,\n"
                "2 bad input.");
  auto o = std::make_shared<MergeCommandOptions>();
  merge->add_option("maps", o->maps, "Two or more maps: PNG/PGM images or map_server YAML files (the first is the reference)")
      ->required();
  // Checked by check_merge_method, which also says the new name of a renamed method.
  merge->add_option("--method", o->method, "Alignment method: auto, grid or features (see below)")->capture_default_str();
  merge->add_option("--set", o->set,
                    "A merge method's parameter, METHOD.KEY=VALUE (repeat for more), e.g. --set features.ratio=0.7 or "
                    "--set grid.sweep_step_deg=2: for --method's own, or under auto for any method it runs "
                    "(parameters listed below)")
      ->expected(1)
      ->take_all();
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
