#include "mapping/distance_field.h"

#include <opencv2/imgproc.hpp>

namespace fleetmap::mapping {

std::vector<float> distance_to_blocked(int width, int height, const std::vector<std::uint8_t>& blocked,
                                       bool outside_blocked) {
  std::vector<float> out(std::size_t(width) * std::size_t(height), 0.0f);
  if (width <= 0 || height <= 0) return out;
  // OpenCV measures the distance to the nearest zero pixel (exact with DIST_MASK_PRECISE). The
  // border ring, when asked for, is a frame of zeros; otherwise the image is the grid itself.
  const int pad = outside_blocked ? 1 : 0;
  cv::Mat open(height + 2 * pad, width + 2 * pad, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < height; ++y) {
    auto* row = open.ptr<std::uint8_t>(y + pad);
    for (int x = 0; x < width; ++x) row[x + pad] = blocked[std::size_t(y) * std::size_t(width) + std::size_t(x)] ? 0 : 255;
  }
  cv::Mat distance;
  cv::distanceTransform(open, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  for (int y = 0; y < height; ++y) {
    const float* d = distance.ptr<float>(y + pad);
    for (int x = 0; x < width; ++x) out[std::size_t(y) * std::size_t(width) + std::size_t(x)] = d[x + pad];
  }
  return out;
}

}  // namespace fleetmap::mapping
