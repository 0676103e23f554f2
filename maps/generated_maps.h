#pragma once
// How the built-in maps of maps/ are made (generate_maps and its test). Internal: the images are
// OpenCV matrices, so this header is not installed.
#include <opencv2/core/mat.hpp>

#include <string>
#include <string_view>

#include "io/map_io.h"

namespace fleetmap::maps {

struct GeneratedMap {
  cv::Mat image;          // 8-bit grey, 254 free, 0 occupied, top row first
  io::MapYaml yaml;  // image: <name>.png
};

// Deterministic: the same image and YAML on every call. Throws InputError for unknown names.
GeneratedMap generate_builtin_map(std::string_view name);
// The bytes of the committed files: the PNG encoding of the image, and the YAML text.
std::string encode_png(const cv::Mat& image);

}  // namespace fleetmap::maps
