#pragma once
// Map images as OpenCV matrices: decoding, the grid <-> image conversions with map_server's rules,
// encoding and writing. Internal: io/map_io.h has the same for programs that link fleetmap, on
// fleetmap's own MapImage, so this header is not installed.
#include <opencv2/core/mat.hpp>

#include <filesystem>
#include <string>

#include "io/map_io.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::io {

// Decodes the bytes of a PNG or PGM map image, refusing images over `options.max_cells` from their
// header before decoding. Returns 8-bit 1-4 channel pixels; throws InputError naming `source`.
cv::Mat decode_map_image(const std::string& bytes, const std::string& source, const MapLoadOptions& options = {});
// Builds a grid from a decoded image (8-bit, 1 to 4 channels) with map_server's rules.
mapping::OccupancyGrid grid_from_image(const cv::Mat& image, const MapYaml& meta,
                              const mapping::OccupancyGridOptions& grid_options = {});
// The map_saver image: 254 free, 0 occupied, 205 unknown, 8-bit single channel, top row first.
cv::Mat grid_to_image(const mapping::OccupancyGrid& grid);

// PNG bytes of an 8- or 16-bit image of 1, 3 (BGR) or 4 (BGRA) channels, byte for byte what OpenCV's
// cv::imencode(".png") writes with the same level (libpng with OpenCV's settings; fleetmap does not
// link OpenCV's image-file module: it pulls in over a hundred libraries a program loads at start).
// compression_level < 0: OpenCV's fast default; 0-9: zlib's level. Empty for other images.
std::string encode_png(const cv::Mat& image, int compression_level = -1);

// The bytes of `image` in the format an extension names (".png", ".pgm"). Throws InputError
// naming `what` when fleetmap cannot write that format for this image.
std::string encode_image(const std::string& extension, const cv::Mat& image, const std::string& what);

// Encodes `image` (extension picks the format) and writes it atomically.
void write_image(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace fleetmap::io
