// Writes every built-in map (PNG + YAML) into a folder, by default the maps/ folder beside this
// file. The committed files are this program's output; tests/maps checks they still match.
//   build/maps/fleetmap_generate_maps [OUT_DIR]
#include <fmt/format.h>
#include <cstdio>
#include <exception>
#include <filesystem>

#include "io/file_io.h"
#include "maps/builtin_maps.h"
#include "maps/generated_maps.h"

int main(int argc, char** argv) {
  namespace fm = fleetmap;
  try {
    const std::filesystem::path out = argc > 1 ? std::filesystem::path(argv[1]) : fm::maps::builtin_maps_dir();
    for (const auto& info : fm::maps::builtin_maps()) {
      const auto m = fm::maps::generate_builtin_map(info.name);
      fm::io::write_file_atomic(out / (info.name + ".png"), fm::maps::encode_png(m.image));
      fm::io::write_file_atomic(out / (info.name + ".yaml"), fm::io::format_map_yaml(m.yaml));
      fmt::print("{:<13} {:>4}x{:<4} -> {}\n", info.name, m.image.cols, m.image.rows, (out / (info.name + ".png")).string());
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "fleetmap_generate_maps: {}\n", e.what());
    return 1;
  }
  return 0;
}
