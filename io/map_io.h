#pragma once
// Map files: PNG/PGM images and ROS map_server YAML, with map_server's semantics
// (image row 0 is the top, cell row 0 the bottom; occ = (255 - mean(RGB)) / 255, inverted by
// `negate`; Occupied when occ > occupied_thresh, Free when occ < free_thresh). A pixel less than
// half opaque (alpha < 128) is Unknown: a transparent background was never drawn on.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/range.h"
#include "core/transform2.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::io {

enum class MapMode { Trinary, Scale, Raw };

// Metres per cell a map may have (map YAML files and --resolution alike), and how far its origin
// may be from zero, in metres: anything beyond is a typing error, not a map.
inline constexpr core::Range kResolutionRange{1e-4, 1000};
inline constexpr core::Range kOriginRange{-1e7, 1e7};

// The keys of a map_server YAML file, with map_server's defaults.
struct MapYaml {
  std::filesystem::path image;  // as written: relative paths are relative to the YAML's folder
  double resolution = 0.05;     // metres per cell
  core::Pose2 origin;           // pose of the lower-left corner of the map
  bool negate = false;
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  MapMode mode = MapMode::Trinary;
};

struct MapLoadOptions {
  // Larger images are refused before they are decoded (64 M cells = 8000 x 8000).
  std::int64_t max_cells = 64'000'000;
  // A bare image has no YAML: it gets this resolution and origin (0, 0, 0).
  double default_resolution = 0.05;
  mapping::OccupancyGridOptions grid;
};

// Parses a map_server YAML text. `source` names it in errors. Unknown keys, missing `image` or
// `resolution`, and bad values throw InputError naming the source, the key and its line.
MapYaml parse_map_yaml(std::string_view text, const std::string& source);
// The YAML text map_saver writes (the image path as given).
std::string format_map_yaml(const MapYaml& yaml);

// A map image as map_saver writes it: 8-bit grey, 254 free, 0 occupied, 205 unknown, row-major,
// top row first (image row 0 is the map's last cell row).
struct MapImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width * height
};
// The map_saver image of a grid.
MapImage map_image(const mapping::OccupancyGrid& grid);
// A grid from a grey image with map_server's rules (`meta`'s thresholds, mode, resolution and
// origin). Throws InputError when the pixels are not width * height or the image is empty.
mapping::OccupancyGrid grid_from_map_image(const MapImage& image, const MapYaml& meta,
                                           const mapping::OccupancyGridOptions& grid_options = {});

// Loads a map from a map_server YAML (.yaml / .yml) or an image (PNG, PGM, ...).
// Throws InputError naming the file for anything missing, unreadable, empty or too large.
mapping::OccupancyGrid load_map(const std::filesystem::path& path, const MapLoadOptions& options = {});

// What a user should know about how load_map(path, options) read the map, one line each: the
// resolution a bare image took, when it was not the user's choice (`resolution_source` says where
// it came from, e.g. "the default; --resolution sets it"; empty: the user gave it), and pixels read
// in a way that may surprise (transparent ones; grey between the thresholds, read as unknown;
// colours, read by their mean). Empty when nothing needs saying. Throws as load_map does.
std::vector<std::string> map_reading_notes(const std::filesystem::path& path, const MapLoadOptions& options,
                                           const std::string& resolution_source);

// The files load_map(path) reads: a map_server YAML and the image it names, or the image alone.
// For checks that no output replaces an input; a YAML that cannot be read gives just itself.
std::vector<std::filesystem::path> map_files(const std::filesystem::path& path);

// Throws InputError (before any work) unless pictures can be written to `path`: a .png name, or
// the standard output ("-", which gets PNG).
void check_picture_path(const std::filesystem::path& path, const std::string& what);

// Saves the map_saver image of the grid as PNG or PGM (by extension).
void save_map_image(const mapping::OccupancyGrid& grid, const std::filesystem::path& path);
// Saves `<yaml_path stem>.pgm` beside the YAML and the YAML that map_server loads back.
void save_map_yaml(const mapping::OccupancyGrid& grid, const std::filesystem::path& yaml_path);

// A map file an output path names: a map_server map (.yaml / .yml, with `<stem>.pgm` beside it) or
// a bare map image (.pgm, map_saver's 0 / 254 / 205). Other names are not map files.
bool is_map_file_name(const std::filesystem::path& path);
// The files save_map(grid, path) writes: the YAML and its image, or the image alone.
std::vector<std::filesystem::path> map_output_files(const std::filesystem::path& path);
// Saves the grid as the map file `path` names (see is_map_file_name); throws InputError otherwise.
void save_map(const mapping::OccupancyGrid& grid, const std::filesystem::path& path);

}  // namespace fleetmap::io
