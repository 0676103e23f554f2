// Fuzzes the map_server YAML parser, then builds a grid from a small fixed image with what it
// parsed (resolution, origin, negate, thresholds, mode all reach the grid).
#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "core/error.h"
#include "io/map_image.h"
#include "io/map_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = fleetmap::io;
  namespace mapping = fleetmap::mapping;
  static const cv::Mat image = [] {
    cv::Mat m(7, 5, CV_8UC1);
    for (int i = 0; i < m.rows * m.cols; ++i) m.data[i] = static_cast<unsigned char>(i * 37);
    return m;
  }();
  try {
    const io::MapYaml meta =
        io::parse_map_yaml(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    const mapping::OccupancyGrid grid = io::grid_from_image(image, meta);
    // What map_saver would write loads back to the same settings.
    const io::MapYaml back = io::parse_map_yaml(io::format_map_yaml(meta), "round-trip.yaml");
    if (back.image != meta.image || back.resolution != meta.resolution || !(back.origin == meta.origin) ||
        back.negate != meta.negate || back.mode != meta.mode || back.occupied_thresh != meta.occupied_thresh ||
        back.free_thresh != meta.free_thresh) {
      __builtin_trap();
    }
    (void)grid;
  } catch (const fleetmap::InputError&) {
  }
  return 0;
}
