// Fuzzes the map image decoder (PNG, PGM and whatever else OpenCV recognises) and the map_server
// conversion of the decoded pixels into an occupancy grid.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "io/map_image.h"
#include "io/map_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = fleetmap::io;
  namespace mapping = fleetmap::mapping;
  io::MapLoadOptions options;
  options.max_cells = 1 << 22;  // keeps every input quick; the limit itself is part of what is tested
  try {
    const cv::Mat image =
        io::decode_map_image(std::string(reinterpret_cast<const char*>(data), size), "fuzz.png", options);
    const mapping::OccupancyGrid grid = io::grid_from_image(image, io::MapYaml{}, options.grid);
    if (grid.geometry().width() != image.cols || grid.geometry().height() != image.rows) __builtin_trap();
  } catch (const fleetmap::InputError&) {
  }
  return 0;
}
