#pragma once
// The built-in maps: the wave-algorithm paper's four 200x200 environments (Fig. 5: empty, unstructured, office,
// corridor) and more (cave, maze, warehouse, campus). Each is a PNG + map_server YAML pair in
// maps/, made by generate_builtin_map(); regenerating gives the committed files bit for bit.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/registry.h"
#include "io/map_io.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::maps {

struct BuiltinMapInfo {
  std::string name;
  std::string description;
};

// Makes a map by name, with the load options of the command that asks for it.
using MapFactory = std::function<mapping::OccupancyGrid(const io::MapLoadOptions&)>;

// Every map a name stands for: the generated ones of maps/, then those registered by the program.
core::Registry<MapFactory>& map_registry();
// Adds a named map: `--map NAME`, scenario files and sweeps reach it. Throws Error when taken.
void register_map(std::string name, std::string description, MapFactory make);

// In the order `fleetmap maps list` shows them.
std::vector<BuiltinMapInfo> builtin_maps();
bool is_builtin_map(std::string_view name);
// "empty, unstructured, ..." for messages.
std::string builtin_map_names();

// Where the built-in map files live: $FLEETMAP_MAPS_DIR if set, else the source tree's maps/,
// else <executable>/../share/fleetmap/maps.
std::filesystem::path builtin_maps_dir();

// Loads a map named by the user: an existing PNG/PGM/YAML file, or a built-in map name.
// Throws InputError that names the input, listing the built-in names when it is neither.
mapping::OccupancyGrid load_map_source(const std::string& name_or_path,
                                       const io::MapLoadOptions& options = {});
// The files load_map_source reads for `name_or_path` (a built-in map's PNG and YAML too), so that
// no output is ever written over them.
std::vector<std::filesystem::path> map_source_files(const std::string& name_or_path);

}  // namespace fleetmap::maps
