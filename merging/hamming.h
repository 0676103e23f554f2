#pragma once
// Nearest binary descriptors (internal: OpenCV types).
#include <opencv2/core.hpp>
#include <vector>

namespace fleetmap::merging {

// For each row of `query`, the nearest and second-nearest rows of `train` by Hamming distance
// (binary descriptors: CV_8U rows of equal width), as cv::BFMatcher(cv::NORM_HAMMING).knnMatch(query,
// train, k = 2) finds them: on a tie the lower index comes first. OpenCV's matcher spends about 120
// instructions per pair of 32-byte descriptors in Debian's build (a trace region and a hardware check
// around each distance); this loop a tenth of that. Throws InputError for rows of different widths,
// another type, or fewer than two rows in `train`.
struct NearestTwo {
  int index = -1;           // train row of the nearest
  int distance = 0;         // to the nearest
  int second_distance = 0;  // to the second nearest
};
std::vector<NearestTwo> nearest_two_hamming(const cv::Mat& query, const cv::Mat& train);

}  // namespace fleetmap::merging
